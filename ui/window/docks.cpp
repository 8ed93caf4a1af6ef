#include "window/docks.hpp"

#include "document/miss_navigator.hpp"
#include "panels/explain_panel.hpp"
#include "panels/property_panel.hpp"
#include "panels/report_dock.hpp"
#include "panels/scene_tree.hpp"
#include "panels/tile_inspector.hpp"
#include "widgets/message_log.hpp"

#include <QComboBox>
#include <QDockWidget>
#include <QHBoxLayout>
#include <QLineEdit>
#include <QMainWindow>
#include <QScrollArea>
#include <QScrollBar>
#include <QTimer>
#include <QVBoxLayout>

#include <algorithm>

namespace lcui {

Docks::Docks(QMainWindow* window, Document* doc, MissNavigator* misses, CullService* service)
    : QObject(window), window_(window) {
    tree_ = new SceneTree(doc);
    tree_->setObjectName("sceneTree");
    properties_ = new PropertyPanel(doc);
    properties_->setObjectName("propertyPanel");
    tileInspector_ = new TileInspector(doc);
    tileInspector_->setObjectName("tileInspector");
    explain_ = new ExplainPanel(doc);
    explain_->setObjectName("explainPanel");
    log_ = new MessageLog;
    report_ = new ReportDock(doc, service);

    sceneDock_ = dock(tr("Scene"), "sceneDock", scenePane(), Qt::LeftDockWidgetArea);
    propertiesDock_ = dock(tr("Properties"), "propertiesDock", propertiesPane(), Qt::LeftDockWidgetArea);
    QDockWidget* tileDock = tileDock_ = dock(tr("Tile inspector"), "tileDock", tileInspector_, Qt::RightDockWidgetArea);
    QDockWidget* explainDock = dock(tr("Explain"), "explainDock", explain_, Qt::RightDockWidgetArea);
    connect(misses, &MissNavigator::missSelected, this, [explainDock] {
        explainDock->show();
        explainDock->raise();
    });
    window_->splitDockWidget(tileDock, explainDock, Qt::Vertical);
    QDockWidget* logDock = logDock_ = dock(tr("Message log"), "logDock", log_, Qt::BottomDockWidgetArea);
    // The Report's chart and table scroll inside their dock, so that the
    // bottom area can be a strip of a few log lines.
    auto* reportScroll = new QScrollArea;
    reportScroll->setWidget(report_);
    reportScroll->setWidgetResizable(true);
    reportScroll->setFrameShape(QFrame::NoFrame);
    QDockWidget* reportDock = dock(tr("Report"), "reportDock", reportScroll, Qt::BottomDockWidgetArea);
    window_->tabifyDockWidget(logDock, reportDock);
    // A first start shows the log; the Report tab is one click away (a saved
    // layout wins).
    logDock->raise();
    growReportTab(logDock, reportDock);
}

QDockWidget* Docks::dock(const QString& title, const char* name, QWidget* w, Qt::DockWidgetArea area) {
    auto* d = new QDockWidget(title, window_);
    d->setObjectName(name);
    d->setWidget(w);
    window_->addDockWidget(area, d);
    return d;
}

// The scene tree with a filter box and the light order above it.
QWidget* Docks::scenePane() {
    auto* pane = new QWidget;
    auto* filter = new QLineEdit;
    filter->setObjectName("sceneFilter");
    filter->setPlaceholderText(tr("Filter lights by name or index"));
    filter->setClearButtonEnabled(true);
    connect(filter, &QLineEdit::textChanged, tree_, &SceneTree::setLightFilter);
    auto* sort = new QComboBox;
    sort->setObjectName("sceneSort");
    sort->addItem(tr("by index"), int(SceneTree::LightSort::Index));
    sort->addItem(tr("by name"), int(SceneTree::LightSort::Name));
    sort->addItem(tr("by radius"), int(SceneTree::LightSort::Radius));
    sort->addItem(tr("by tiles reached"), int(SceneTree::LightSort::TilesReached));
    connect(sort, qOverload<int>(&QComboBox::currentIndexChanged), this,
            [this, sort] { tree_->setLightSort(SceneTree::LightSort(sort->currentData().toInt())); });
    auto* row = new QHBoxLayout;
    row->addWidget(filter, 1);
    row->addWidget(sort);
    auto* col = new QVBoxLayout(pane);
    col->setContentsMargins(0, 0, 0, 0);
    col->addLayout(row);
    col->addWidget(tree_, 1);
    return pane;
}

// The properties scroll inside their dock: a spot light's fields are 400 px
// tall, and as the dock's minimum they would keep the bottom area a strip on a
// laptop's screen.
QWidget* Docks::propertiesPane() {
    auto* scroll = new QScrollArea;
    scroll->setWidget(properties_);
    scroll->setWidgetResizable(true);
    scroll->setFrameShape(QFrame::NoFrame);
    scroll->setHorizontalScrollBarPolicy(Qt::ScrollBarAlwaysOff);
    scroll->setMinimumWidth(properties_->minimumSizeHint().width() + scroll->verticalScrollBar()->sizeHint().width());
    return scroll;
}

// The log is a strip of a few lines; the Report's chart is not readable in
// one. Raising the Report tab grows the bottom area to a readable height, and
// raising the log again gives the strip back, unless the user has resized it
// in between. Deferred: while the tab bar switches, the dock layout has not
// yet taken the new tab.
void Docks::growReportTab(QDockWidget* logDock, QDockWidget* reportDock) {
    connect(reportDock, &QDockWidget::visibilityChanged, this, [this, reportDock](bool visible) {
        if (!visible || reportDock->isFloating()) return;
        QTimer::singleShot(0, this, [this, reportDock] {
            const int want = std::clamp(window_->height() * 45 / 100, 120, 420);
            if (!reportDock->isVisible() || reportDock->isFloating() || reportDock->height() >= want) return;
            stripHeight_ = reportDock->height();
            window_->resizeDocks({reportDock}, {want}, Qt::Vertical);
            // What the docks around let it have (the left and right columns'
            // minimum heights bound it).
            QTimer::singleShot(0, this, [this, reportDock] { grownHeight_ = reportDock->height(); });
        });
    });
    connect(logDock, &QDockWidget::visibilityChanged, this, [this, logDock](bool visible) {
        if (!visible || logDock->isFloating() || grownHeight_ == 0) return;
        QTimer::singleShot(0, this, [this, logDock] {
            // Only the height the Report tab set is given back.
            if (logDock->isVisible() && std::abs(logDock->height() - grownHeight_) <= 2)
                window_->resizeDocks({logDock}, {stripHeight_}, Qt::Vertical);
            grownHeight_ = 0;
        });
    });
}

void Docks::initialSizes() {
    window_->resizeDocks({logDock_}, {110}, Qt::Vertical);
    window_->resizeDocks({sceneDock_, propertiesDock_}, {420, 300}, Qt::Vertical);
    window_->resizeDocks({sceneDock_, tileDock_}, {260, 330}, Qt::Horizontal);
}

} // namespace lcui
