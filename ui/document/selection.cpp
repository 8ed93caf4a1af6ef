#include "document/selection.hpp"

#include <algorithm>

namespace lcui {

Selection::Selection(const lc::Scene& scene, QObject* parent) : QObject(parent), scene_(scene) {}

void Selection::setSelectedLights(std::vector<int> lights) {
    const int n = int(scene_.lights.size());
    std::erase_if(lights, [n](int i) { return i < 0 || i >= n; });
    // Deduplicate keeping the order: the last one is the current light.
    std::vector<int> unique;
    for (int i : lights)
        if (std::find(unique.begin(), unique.end(), i) == unique.end()) unique.push_back(i);
    if (unique == lights_ && !camera_) return;
    lightLast_ = !unique.empty();
    lights_ = std::move(unique);
    camera_ = false;
    ++revision_;
    emit changed();
}

void Selection::selectCamera() {
    lights_.clear();
    camera_ = true;
    ++revision_;
    emit changed();
}

void Selection::setSelectedTile(int tile) {
    if (tile == tile_) return;
    tile_ = tile;
    if (tile >= 0) lightLast_ = false;
    cell_ = -1;
    explainedList_ = -1;
    ++revision_;
    emit tileChanged(tile);
}

void Selection::setSelectedCell(int cell) {
    if (cell == cell_) return;
    cell_ = cell;
    explainedList_ = -1;
    ++revision_;
    emit tileChanged(tile_);
}

void Selection::setExplainedList(int list) {
    if (list == explainedList_) return;
    explainedList_ = list;
    ++revision_;
    emit changed();
}

void Selection::reset() {
    lights_.clear();
    camera_ = lightLast_ = false;
    tile_ = cell_ = explainedList_ = -1;
    ++revision_;
}

void Selection::replaceLights(std::vector<int> lights, bool deselectCamera) {
    lights_ = std::move(lights);
    if (deselectCamera) camera_ = false;
    ++revision_;
}

void Selection::clearTile() {
    tile_ = cell_ = explainedList_ = -1;
    ++revision_;
}

} // namespace lcui
