#pragma once
// The tile inspector dock: the selected tile's light lists (index, name,
// radius, which of the tile's lists holds it). A placeholder for the overlays
// issue, which adds per-pixel need counts and ground-truth verdicts here.

#include <QTableWidget>

namespace lcui {

class Document;

class TileInspector : public QTableWidget {
    Q_OBJECT
public:
    explicit TileInspector(Document* doc, QWidget* parent = nullptr);
    // Light indices currently listed, in table order.
    std::vector<int> listedLights() const;

private:
    void refresh();
    Document* doc_;
};

} // namespace lcui
