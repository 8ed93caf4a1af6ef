#include "panels/scene_tree.hpp"

#include "document/document.hpp"

#include <QItemSelectionModel>

#include <algorithm>
#include <climits>
#include <cstdint>

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
    connect(&doc_->selection(), &Selection::changed, this, &SceneTree::syncFromDocument);
    connect(&doc_->runs(), &RunState::runOutputChanged, this, [this] {
        if (sort_ == LightSort::TilesReached) setLightSort(sort_); // the counts changed
    });
}

QModelIndex SceneTree::lightIndex(int i) const {
    if (!lights_ || i < 0 || std::size_t(i) >= rowOfLight_.size()) return {};
    const int row = rowOfLight_[std::size_t(i)];
    return row < lights_->rowCount() ? lights_->child(row)->index() : QModelIndex();
}

void SceneTree::setLightFilter(const QString& text) {
    filter_ = text.trimmed();
    applyFilter();
}

void SceneTree::applyFilter() {
    if (!lights_) return;
    for (int row = 0; row < lights_->rowCount(); ++row)
        setRowHidden(row, lights_->index(),
                     !filter_.isEmpty() && !lights_->child(row)->text().contains(filter_, Qt::CaseInsensitive));
}

void SceneTree::setLightSort(LightSort sort) {
    sort_ = sort;
    rebuildLights();
    syncFromDocument();
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
    order_.resize(lights.size());
    for (std::size_t i = 0; i < lights.size(); ++i) order_[i] = int(i);
    if (sort_ == LightSort::Name) {
        std::stable_sort(order_.begin(), order_.end(), [&](int a, int b) { return lights[std::size_t(a)].name < lights[std::size_t(b)].name; });
    } else if (sort_ == LightSort::Radius) {
        std::vector<double> r(lights.size());
        for (std::size_t i = 0; i < lights.size(); ++i) r[i] = lights[i].validate().empty() ? lights[i].radius() : 0.0;
        std::stable_sort(order_.begin(), order_.end(), [&](int a, int b) { return r[std::size_t(a)] > r[std::size_t(b)]; });
    } else if (sort_ == LightSort::TilesReached) {
        std::vector<std::size_t> tiles(lights.size(), 0);
        if (const auto run = doc_->runs().runOutput(); run && run->result.algorithm != lc::Algorithm::All) {
            // One pass over the lists: each light's distinct tiles.
            const auto& res = run->result;
            std::vector<std::uint32_t> lastTile(lights.size(), UINT32_MAX);
            for (std::uint32_t l = 0; l < res.listCount.size(); ++l)
                for (std::uint32_t k = 0; k < res.listCount[l]; ++k) {
                    const std::uint32_t light = res.lightIndices[res.listOffset[l] + k];
                    if (light < lights.size() && lastTile[light] != res.tileOfList(l)) {
                        lastTile[light] = res.tileOfList(l);
                        ++tiles[light];
                    }
                }
        }
        std::stable_sort(order_.begin(), order_.end(), [&](int a, int b) { return tiles[std::size_t(a)] > tiles[std::size_t(b)]; });
    }
    rowOfLight_.assign(lights.size(), 0);
    QList<QStandardItem*> rows;
    rows.reserve(int(lights.size()));
    for (std::size_t row = 0; row < order_.size(); ++row) {
        auto* it = new QStandardItem;
        it->setData(KindLight, kKindRole);
        it->setData(order_[row], kIndexRole);
        rowOfLight_[std::size_t(order_[row])] = int(row);
        rows.append(it);
    }
    for (auto* r : rows) lights_->appendRow(r);
    for (std::size_t i = 0; i < lights.size(); ++i) updateLightRow(int(i));
    lights_->setText(tr("Lights (%1)").arg(lights.size()));
    applyFilter();
    syncing_ = false;
}

void SceneTree::updateLightRow(int i) {
    const auto& lights = doc_->scene().lights;
    if (!lights_ || i < 0 || std::size_t(i) >= rowOfLight_.size() || i >= int(lights.size())) return;
    const auto& l = lights[std::size_t(i)];
    const QString name = l.name.empty() ? tr("light") : QString::fromStdString(l.name);
    lights_->child(rowOfLight_[std::size_t(i)])->setText(QStringLiteral("%1  %2").arg(i).arg(name));
}

void SceneTree::syncFromDocument() {
    if (syncing_) return;
    syncing_ = true;
    QItemSelection sel;
    for (int i : doc_->selection().selectedLights()) {
        const QModelIndex idx = lightIndex(i);
        if (idx.isValid()) sel.select(idx, idx);
    }
    if (doc_->selection().cameraSelected() && camera_) sel.select(camera_->index(), camera_->index());
    selectionModel()->select(sel, QItemSelectionModel::ClearAndSelect);
    if (!doc_->selection().selectedLights().empty()) scrollTo(lightIndex(doc_->selection().currentLight()));
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
    if (lights.empty() && camera) doc_->selection().selectCamera();
    else doc_->selection().setSelectedLights(lights);
    syncing_ = false;
}

} // namespace lcui
