#pragma once
// The window's docks and the panels in them: the scene tree with its filter
// and order, the properties (scrolling inside their dock), the tile inspector
// over Explain, and the message log tabbed with the Report, whose tab grows
// the bottom area to a readable height and gives the log its strip back.

#include <QObject>

class QDockWidget;
class QMainWindow;

namespace lcui {

class CullService;
class Document;
class ExplainPanel;
class MessageLog;
class MissNavigator;
class PropertyPanel;
class ReportDock;
class SceneTree;
class TileInspector;

class Docks : public QObject {
    Q_OBJECT
public:
    Docks(QMainWindow* window, Document* doc, MissNavigator* misses, CullService* service);

    SceneTree* tree() const { return tree_; }
    PropertyPanel* properties() const { return properties_; }
    TileInspector* tileInspector() const { return tileInspector_; }
    ExplainPanel* explain() const { return explain_; }
    MessageLog* log() const { return log_; }
    ReportDock* report() const { return report_; }
    // First start: views get the room, the log stays a strip at the bottom,
    // the scene tree is tall and the tile inspector and Explain are wide
    // enough for their columns (a saved layout wins from then on).
    void initialSizes();

private:
    QDockWidget* dock(const QString& title, const char* name, QWidget* w, Qt::DockWidgetArea area);
    QWidget* scenePane();
    QWidget* propertiesPane();
    void growReportTab(QDockWidget* logDock, QDockWidget* reportDock);

    QMainWindow* window_;
    SceneTree* tree_;
    PropertyPanel* properties_;
    TileInspector* tileInspector_;
    ExplainPanel* explain_;
    MessageLog* log_;
    ReportDock* report_;
    QDockWidget *sceneDock_, *propertiesDock_, *tileDock_, *logDock_;
    // The bottom area's height before the Report tab grew it, and what it grew
    // it to (0: not grown).
    int stripHeight_ = 0, grownHeight_ = 0;
};

} // namespace lcui
