#include "panels/tile_inspector.hpp"

#include "document/document.hpp"

#include <QBrush>
#include <QColor>
#include <QHeaderView>
#include <QLabel>
#include <QSortFilterProxyModel>
#include <QRegularExpression>
#include <QComboBox>
#include <QTableView>
#include <QVBoxLayout>

namespace lcui {

TileLightsModel::TileLightsModel(Document* doc, QObject* parent) : QAbstractTableModel(parent), doc_(doc) {}

int TileLightsModel::rowCount(const QModelIndex& parent) const { return parent.isValid() ? 0 : int(rows_.size()); }
int TileLightsModel::columnCount(const QModelIndex& parent) const { return parent.isValid() ? 0 : ColumnCount; }

QVariant TileLightsModel::headerData(int section, Qt::Orientation o, int role) const {
    if (o != Qt::Horizontal || role != Qt::DisplayRole) return {};
    static const char* kNames[ColumnCount] = {"light", "name", "verdict", "pixels", "list", "radius", "position"};
    return section >= 0 && section < ColumnCount ? tr(kNames[section]) : QVariant();
}

void TileLightsModel::setRows(std::vector<lc::TileLightRow> rows, std::shared_ptr<const lc::RunOutput> run) {
    beginResetModel();
    rows_ = std::move(rows);
    run_ = std::move(run);
    endResetModel();
}

QVariant TileLightsModel::data(const QModelIndex& index, int role) const {
    if (!index.isValid() || index.row() >= int(rows_.size())) return {};
    const lc::TileLightRow& r = rows_[std::size_t(index.row())];
    const auto& lights = doc_->scene().lights;
    if (role == Qt::BackgroundRole && r.verdict == lc::Verdict::Missing) return QBrush(QColor(200, 40, 40));
    if (role == Qt::ForegroundRole) {
        if (r.verdict == lc::Verdict::Missing) return QBrush(Qt::white);
        if (r.verdict == lc::Verdict::FalsePositive) return QBrush(QColor(130, 130, 130));
    }
    if (role == Qt::TextAlignmentRole && index.column() != ColName && index.column() != ColVerdict)
        return int(Qt::AlignRight | Qt::AlignVCenter);
    if (role != Qt::DisplayRole && role != Qt::EditRole) return {};
    // The run may be older than the scene: a removed light has no name.
    const bool inScene = r.light < lights.size();
    switch (index.column()) {
    case ColList: return int(r.list);
    case ColLight: return int(r.light);
    case ColName: return inScene ? QString::fromStdString(lights[r.light].name) : QString();
    case ColPosition: {
        if (!inScene) return QString();
        const auto& p = lights[r.light].position;
        return QString("%1, %2, %3").arg(p.x, 0, 'g', 4).arg(p.y, 0, 'g', 4).arg(p.z, 0, 'g', 4);
    }
    case ColRadius: {
        if (!run_ || r.light >= run_->lights.size()) return {};
        const double radius = run_->lights.radii[r.light];
        // Shown to 4 digits; sorted by the number (the proxy sorts EditRole).
        return role == Qt::EditRole ? QVariant(radius) : QVariant(QString::number(radius, 'g', 4));
    }
    case ColPixels: return int(r.pixelsNeeding);
    case ColVerdict: return QString(lc::toString(r.verdict));
    }
    return {};
}

TileInspector::TileInspector(Document* doc, QWidget* parent) : QWidget(parent), doc_(doc) {
    model_ = new TileLightsModel(doc_, this);
    // Rows sort by any column (click its header) and filter by verdict.
    proxy_ = new QSortFilterProxyModel(this);
    proxy_->setObjectName("tileLightsProxy");
    proxy_->setSourceModel(model_);
    proxy_->setFilterKeyColumn(TileLightsModel::ColVerdict);
    proxy_->setSortRole(Qt::EditRole);
    verdictFilter_ = new QComboBox;
    verdictFilter_->setObjectName("tileVerdictFilter");
    verdictFilter_->addItem(tr("All rows"), QString());
    verdictFilter_->addItem(tr("Needed"), QStringLiteral("needed"));
    verdictFilter_->addItem(tr("False positives"), QStringLiteral("false positive"));
    verdictFilter_->addItem(tr("MISSING"), QStringLiteral("MISSING"));
    connect(verdictFilter_, qOverload<int>(&QComboBox::currentIndexChanged), this, [this] {
        const QString v = verdictFilter_->currentData().toString();
        proxy_->setFilterRegularExpression(v.isEmpty() ? QRegularExpression()
                                                       : QRegularExpression("^" + QRegularExpression::escape(v) + "$"));
    });
    table_ = new QTableView;
    table_->setObjectName("tileLightsTable");
    table_->setModel(proxy_);
    table_->setSortingEnabled(true);
    table_->sortByColumn(-1, Qt::AscendingOrder); // the model's order until a header is clicked
    table_->horizontalHeader()->setStretchLastSection(true);
    table_->verticalHeader()->hide();
    table_->setEditTriggers(QAbstractItemView::NoEditTriggers);
    table_->setSelectionBehavior(QAbstractItemView::SelectRows);
    summary_ = new QLabel;
    summary_->setObjectName("tileSummary");
    summary_->setWordWrap(true);
    auto* l = new QVBoxLayout(this);
    l->setContentsMargins(2, 2, 2, 2);
    l->addWidget(summary_);
    l->addWidget(verdictFilter_);
    l->addWidget(table_, 1);
    connect(&doc_->selection(), &Selection::tileChanged, this, &TileInspector::refresh);
    connect(&doc_->runs(), &RunState::runOutputChanged, this, &TileInspector::refresh);
    connect(&doc_->runs(), &RunState::runWentStale, this, &TileInspector::refresh);
    // The highlighted row follows the current light wherever it was chosen
    // (scene tree, 3D view, this table): a row left highlighted beside
    // Explain's text about another light misleads.
    connect(&doc_->selection(), &Selection::changed, this, &TileInspector::showCurrentLight);
    connect(table_, &QTableView::doubleClicked, this, [this](const QModelIndex& shown) {
        const QModelIndex i = proxy_->mapToSource(shown);
        if (!i.isValid() || i.row() >= int(model_->rows().size())) return;
        const lc::TileLightRow& row = model_->rows()[std::size_t(i.row())];
        // The row's own list: a halfz or clustered tile has several.
        doc_->selection().setExplainedList(int(row.list));
        doc_->selection().setSelectedLights({int(row.light)});
    });
    refresh();
}

void TileInspector::showCurrentLight() {
    const int light = doc_->selection().currentLight();
    const int list = doc_->selection().explainedList();
    QItemSelectionModel* sel = table_->selectionModel();
    QModelIndex first;
    QItemSelection rows;
    for (int r = 0; r < proxy_->rowCount(); ++r) {
        const QModelIndex src = proxy_->mapToSource(proxy_->index(r, 0));
        const lc::TileLightRow& row = model_->rows()[std::size_t(src.row())];
        // The explained list's row where the tile has several (halfz, clustered).
        if (int(row.light) != light || (list >= 0 && int(row.list) != list)) continue;
        rows.select(proxy_->index(r, 0), proxy_->index(r, proxy_->columnCount() - 1));
        if (!first.isValid()) first = proxy_->index(r, 0);
    }
    sel->select(rows, QItemSelectionModel::ClearAndSelect);
    if (first.isValid()) table_->scrollTo(first);
}

std::vector<int> TileInspector::listedLights() const {
    std::vector<int> out;
    for (const auto& r : model_->rows())
        if (r.verdict != lc::Verdict::Missing) out.push_back(int(r.light));
    return out;
}

QString TileInspector::summaryText() const { return summary_->text(); }

void TileInspector::refresh() {
    const auto run = doc_->runs().runOutput();
    const int tile = doc_->selection().selectedTile();
    const lc::Camera& cam = doc_->scene().camera;
    if (!run || tile < 0 || std::uint32_t(tile) >= run->result.grid.tileCount()) {
        model_->setRows({}, run);
        summary_->setText(run ? tr("Click a tile in the camera view.") : tr("No culling run yet (F5)."));
        return;
    }
    if (doc_->runs().runIsStale()) {
        model_->setRows({}, run);
        summary_->setText(tr("The scene changed since the last run: run culling again (F5)."));
        summary_->setStyleSheet({});
        return;
    }
    if (run->result.grid.width != cam.width || run->result.grid.height != cam.height || !cam.validate().empty()) {
        model_->setRows({}, run);
        summary_->setText(tr("The camera changed since the last run: run culling again."));
        return;
    }
    const lc::Projection proj(cam);
    const int cell = doc_->selection().selectedCell();
    model_->setRows(lc::tileLightRows(*run, proj, std::uint32_t(tile), cell), run);
    // With one list per tile the list column only repeats the tile's index.
    table_->setColumnHidden(TileLightsModel::ColList, run->result.listsPerTile <= 1);
    // Columns as wide as what they hold: light, name, verdict and pixels fit
    // the dock's first-start width.
    table_->resizeColumnsToContents();
    int needed = 0, fp = 0, missing = 0;
    for (const auto& r : model_->rows())
        (r.verdict == lc::Verdict::Needed ? needed : r.verdict == lc::Verdict::FalsePositive ? fp : missing)++;
    const lc::TileGrid& g = run->result.grid;
    QString where = tr("Tile %1, %2").arg(tile % int(g.tilesX)).arg(tile / int(g.tilesX));
    if (cell >= 0) where += tr(", cell %1").arg(cell);
    summary_->setText(tr("%1: %2 needed, %3 false positive, %4 missing")
                          .arg(where)
                          .arg(needed)
                          .arg(fp)
                          .arg(missing));
    summary_->setStyleSheet(missing ? "color: rgb(230,60,60); font-weight: bold" : "");
    showCurrentLight();
}

} // namespace lcui
