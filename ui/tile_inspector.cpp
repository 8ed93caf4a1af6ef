#include "tile_inspector.hpp"

#include "document.hpp"

#include <QHeaderView>

namespace lcui {

TileInspector::TileInspector(Document* doc, QWidget* parent) : QTableWidget(parent), doc_(doc) {
    setColumnCount(4);
    setHorizontalHeaderLabels({tr("list"), tr("light"), tr("name"), tr("radius")});
    horizontalHeader()->setStretchLastSection(true);
    verticalHeader()->hide();
    setEditTriggers(QAbstractItemView::NoEditTriggers);
    setSelectionBehavior(QAbstractItemView::SelectRows);
    connect(doc_, &Document::tileSelectionChanged, this, &TileInspector::refresh);
    connect(doc_, &Document::runOutputChanged, this, &TileInspector::refresh);
    connect(this, &QTableWidget::cellDoubleClicked, this, [this](int row, int) {
        doc_->setSelectedLights({item(row, 1)->text().toInt()});
    });
}

std::vector<int> TileInspector::listedLights() const {
    std::vector<int> out;
    for (int r = 0; r < rowCount(); ++r) out.push_back(item(r, 1)->text().toInt());
    return out;
}

void TileInspector::refresh() {
    setRowCount(0);
    const auto run = doc_->runOutput();
    const int tile = doc_->selectedTile();
    if (!run || tile < 0 || std::uint32_t(tile) >= run->result.grid.tileCount()) return;
    const lc::CullResult& r = run->result;
    const auto& lights = doc_->scene().lights;
    // `all` has one list for every tile; otherwise the tile's listsPerTile lists.
    const std::uint32_t first = r.algorithm == lc::Algorithm::All ? 0 : std::uint32_t(tile) * r.listsPerTile;
    const std::uint32_t n = r.algorithm == lc::Algorithm::All ? 1 : r.listsPerTile;
    for (std::uint32_t s = 0; s < n; ++s) {
        const std::uint32_t list = first + s;
        if (list >= r.listCount.size()) break;
        for (std::uint32_t k = 0; k < r.listCount[list]; ++k) {
            const std::uint32_t li = r.lightIndices[r.listOffset[list] + k];
            const int row = rowCount();
            insertRow(row);
            setItem(row, 0, new QTableWidgetItem(QString::number(s)));
            setItem(row, 1, new QTableWidgetItem(QString::number(li)));
            // The run may be older than the scene: a removed light has no name.
            const bool known = li < run->lights.size();
            setItem(row, 2, new QTableWidgetItem(li < lights.size() ? QString::fromStdString(lights[li].name)
                                                                    : QString()));
            setItem(row, 3, new QTableWidgetItem(known ? QString::number(run->lights.radii[li], 'g', 5)
                                                       : QString()));
        }
    }
}

} // namespace lcui
