#include "scene_tree.hpp"

#include "document.hpp"

#include <QItemSelectionModel>

namespace lcui {

SceneTree::SceneTree(Document* doc, QWidget* parent) : QTreeView(parent), doc_(doc) {
    setModel(&model_);
    setHeaderHidden(true);
    setSelectionMode(QAbstractItemView::ExtendedSelection);
    setEditTriggers(QAbstractItemView::NoEditTriggers);
    setUniformRowHeights(true); // 10k light rows stay fast
    rebuild();
    connect(selectionModel(), &QItemSelectionModel::selectionChanged, this, &SceneTree::syncToDocument);
    connect(doc_, &Document::sceneReset, this, &SceneTree::rebuild);
    connect(doc_, &Document::meshesChanged, this, &SceneTree::rebuild);
    connect(doc_, &Document::lightsChanged, this, [this] {
        rebuildLights();
        syncFromDocument();
    });
    connect(doc_, &Document::lightChanged, this, &SceneTree::updateLightRow);
    connect(doc_, &Document::selectionChanged, this, &SceneTree::syncFromDocument);
}

QModelIndex SceneTree::lightIndex(int i) const {
    return lights_ && i >= 0 && i < lights_->rowCount() ? lights_->child(i)->index() : QModelIndex();
}

void SceneTree::rebuild() {
    syncing_ = true;
    model_.clear();
    const auto& s = doc_->scene();
    meshes_ = new QStandardItem(tr("Meshes"));
    lights_ = new QStandardItem(tr("Lights"));
    camera_ = new QStandardItem(tr("Culling camera"));
    for (auto* g : {meshes_, lights_}) g->setData(KindGroup, kKindRole);
    camera_->setData(KindCamera, kKindRole);
    for (std::size_t i = 0; i < s.meshes.size(); ++i) {
        const auto& m = s.meshes[i];
        auto* it = new QStandardItem(tr("%1 (%2 triangles)")
                                         .arg(QString::fromStdString(m.name.empty() ? "mesh" : m.name))
                                         .arg(m.triangleCount()));
        it->setData(KindMesh, kKindRole);
        it->setData(int(i), kIndexRole);
        meshes_->appendRow(it);
    }
    model_.appendRow(meshes_);
    model_.appendRow(lights_);
    model_.appendRow(camera_);
    syncing_ = false;
    rebuildLights();
    expand(lights_->index());
    syncFromDocument();
}

void SceneTree::rebuildLights() {
    syncing_ = true;
    const auto& lights = doc_->scene().lights;
    lights_->removeRows(0, lights_->rowCount());
    QList<QStandardItem*> rows;
    rows.reserve(int(lights.size()));
    for (std::size_t i = 0; i < lights.size(); ++i) {
        auto* it = new QStandardItem;
        it->setData(KindLight, kKindRole);
        it->setData(int(i), kIndexRole);
        rows.append(it);
    }
    for (auto* r : rows) lights_->appendRow(r);
    for (std::size_t i = 0; i < lights.size(); ++i) updateLightRow(int(i));
    lights_->setText(tr("Lights (%1)").arg(lights.size()));
    syncing_ = false;
}

void SceneTree::updateLightRow(int i) {
    const auto& lights = doc_->scene().lights;
    if (!lights_ || i < 0 || i >= lights_->rowCount() || i >= int(lights.size())) return;
    const auto& l = lights[std::size_t(i)];
    const QString name = l.name.empty() ? tr("light") : QString::fromStdString(l.name);
    lights_->child(i)->setText(QStringLiteral("%1  %2").arg(i).arg(name));
}

void SceneTree::syncFromDocument() {
    if (syncing_) return;
    syncing_ = true;
    QItemSelection sel;
    for (int i : doc_->selectedLights()) {
        const QModelIndex idx = lightIndex(i);
        if (idx.isValid()) sel.select(idx, idx);
    }
    if (doc_->cameraSelected() && camera_) sel.select(camera_->index(), camera_->index());
    selectionModel()->select(sel, QItemSelectionModel::ClearAndSelect);
    if (!doc_->selectedLights().empty()) scrollTo(lightIndex(doc_->currentLight()));
    syncing_ = false;
}

void SceneTree::syncToDocument() {
    if (syncing_) return;
    syncing_ = true;
    std::vector<int> lights;
    bool camera = false;
    for (const QModelIndex& idx : selectionModel()->selectedIndexes()) {
        const int kind = idx.data(kKindRole).toInt();
        if (kind == KindLight) lights.push_back(idx.data(kIndexRole).toInt());
        if (kind == KindCamera) camera = true;
    }
    // The current item decides what the property panel shows: it goes last.
    const QModelIndex cur = currentIndex();
    if (cur.isValid() && cur.data(kKindRole).toInt() == KindLight) {
        const int c = cur.data(kIndexRole).toInt();
        std::erase(lights, c);
        lights.push_back(c);
    }
    if (lights.empty() && camera) doc_->selectCamera();
    else doc_->setSelectedLights(lights);
    syncing_ = false;
}

} // namespace lcui
