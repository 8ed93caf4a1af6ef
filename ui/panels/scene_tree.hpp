#pragma once
// The scene tree dock: meshes, lights and the culling camera, multi-select.
// Selecting lights here selects them in the document (and so in both views);
// the tree follows the document's selection back.

#include <QStandardItemModel>
#include <QTreeView>

#include <vector>

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

    // Light rows whose text (index and name) holds `text`, case-insensitive;
    // the others are hidden. Empty: every row.
    void setLightFilter(const QString& text);
    // Order of the light rows: by index, by name, by radius (largest first) or
    // by the tiles whose lists hold the light in the latest run (most first).
    enum class LightSort { Index, Name, Radius, TilesReached };
    void setLightSort(LightSort sort);
    // Light indices in row order (for tests).
    std::vector<int> lightOrder() const { return order_; }

private:
    void rebuild();
    void rebuildLights();
    void applyFilter();
    void updateLightRow(int i);
    void syncFromDocument();
    void syncToDocument();

    Document* doc_;
    QStandardItemModel model_;
    QStandardItem* meshes_ = nullptr;
    QStandardItem* lights_ = nullptr;
    QStandardItem* camera_ = nullptr;
    bool syncing_ = false;
    QString filter_;
    LightSort sort_ = LightSort::Index;
    std::vector<int> order_;      // row -> light index
    std::vector<int> rowOfLight_; // light index -> row
};

} // namespace lcui
