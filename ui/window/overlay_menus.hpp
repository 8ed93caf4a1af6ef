#pragma once
// View > Overlays, Meshes, Lights and Heat map: every action sets a field of
// the document's OverlayOptions (view_options.hpp) and every check follows
// them, whoever changed them (a test, a script, a restored setting).

#include <QObject>

#include <functional>
#include <vector>

class QMenu;

namespace lcui {

class Document;
struct OverlayOptions;

class OverlayMenus : public QObject {
    Q_OBJECT
public:
    // Adds the four menus to `view`; the actions belong to this object.
    OverlayMenus(Document* doc, QMenu* view, QObject* parent);

private:
    void buildOverlays(QMenu* view);
    void buildMeshes(QMenu* view);
    void buildLights(QMenu* view);
    void buildHeat(QMenu* view);
    void syncAll();
    // A checkable action for one bool of the options.
    void addSwitch(QMenu* menu, const QString& text, const char* name, bool OverlayOptions::*field);

    Document* doc_;
    std::vector<std::function<void()>> syncs_; // one per action: checks it from the options
};

} // namespace lcui
