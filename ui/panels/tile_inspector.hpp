#pragma once
// The tile inspector dock: the selected tile's (or cell's) lights, one row per
// (list, light): index, name, position, radius, how many of the list's pixels
// need it, and the ground-truth verdict (needed / false positive / MISSING).
// Rows come from lc::tileLightRows; a double click selects the light.

#include "culling/diagnostics/overlays.hpp"

#include <QAbstractTableModel>
#include <QWidget>

#include <memory>
#include <vector>

class QComboBox;
class QLabel;
class QSortFilterProxyModel;
class QTableView;

namespace lcui {

class Document;

class TileLightsModel : public QAbstractTableModel {
    Q_OBJECT
public:
    // What answers "why is it here" first: at the dock's first-start width
    // the verdict and pixels show without scrolling.
    enum Column { ColLight, ColName, ColVerdict, ColPixels, ColList, ColRadius, ColPosition, ColumnCount };
    explicit TileLightsModel(Document* doc, QObject* parent = nullptr);
    int rowCount(const QModelIndex& parent = {}) const override;
    int columnCount(const QModelIndex& parent = {}) const override;
    QVariant data(const QModelIndex& index, int role) const override;
    QVariant headerData(int section, Qt::Orientation o, int role) const override;

    void setRows(std::vector<lc::TileLightRow> rows, std::shared_ptr<const lc::RunOutput> run);
    const std::vector<lc::TileLightRow>& rows() const { return rows_; }

private:
    Document* doc_;
    std::vector<lc::TileLightRow> rows_;
    std::shared_ptr<const lc::RunOutput> run_;
};

class TileInspector : public QWidget {
    Q_OBJECT
public:
    explicit TileInspector(Document* doc, QWidget* parent = nullptr);
    // Light indices listed for the selection (verdict needed or false
    // positive), in table order; missing lights are not listed.
    std::vector<int> listedLights() const;
    const std::vector<lc::TileLightRow>& rows() const { return model_->rows(); }
    TileLightsModel* model() const { return model_; }
    // What the table shows: the model sorted and filtered by verdict.
    QSortFilterProxyModel* proxy() const { return proxy_; }
    QComboBox* verdictFilter() const { return verdictFilter_; }
    QTableView* table() const { return table_; }
    QString summaryText() const;

private:
    void refresh();
    // Selects the current light's row(s) (of the explained list, if one is
    // picked), or none.
    void showCurrentLight();
    Document* doc_;
    TileLightsModel* model_;
    QSortFilterProxyModel* proxy_;
    QComboBox* verdictFilter_;
    QTableView* table_;
    QLabel* summary_;
};

} // namespace lcui
