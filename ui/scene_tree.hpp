#pragma once
// The scene tree dock: meshes, lights and the culling camera, multi-select.
// Selecting lights here selects them in the document (and so in both views);
// the tree follows the document's selection back.

#include <QStandardItemModel>
#include <QTreeView>

namespace lcui {

class Document;

class SceneTree : public QTreeView {
    Q_OBJECT
public:
    explicit SceneTree(Document* doc, QWidget* parent = nullptr);

    // Item roles: kKindRole says what a row is, kIndexRole its index.
    enum Kind { KindGroup = 0, KindMesh, KindLight, KindCamera };
    static constexpr int kKindRole = Qt::UserRole + 1;
    static constexpr int kIndexRole = Qt::UserRole + 2;

    QStandardItemModel* sceneModel() { return &model_; }
    // The model index of light i (for tests and scrolling).
    QModelIndex lightIndex(int i) const;

private:
    void rebuild();
    void rebuildLights();
    void updateLightRow(int i);
    void syncFromDocument();
    void syncToDocument();

    Document* doc_;
    QStandardItemModel model_;
    QStandardItem* meshes_ = nullptr;
    QStandardItem* lights_ = nullptr;
    QStandardItem* camera_ = nullptr;
    bool syncing_ = false;
};

} // namespace lcui
