#pragma once
// What the user picked: lights (in selection order), the camera, a tile of the
// culling grid and one of its depth cells, and the list Explain explains. Part
// of the Document (document.hpp), which clears and shifts it as the scene's
// lights and camera change; views and panels observe it.

#include "culling/scene/scene.hpp"

#include <QObject>

#include <vector>

namespace lcui {

class Selection : public QObject {
    Q_OBJECT
public:
    // `scene`: the document's, for the light count the light selection is
    // checked against; it outlives the selection.
    explicit Selection(const lc::Scene& scene, QObject* parent = nullptr);

    // Selected light indices in selection order; currentLight(): the last one
    // (what the property panel and the drag handle act on), or -1.
    const std::vector<int>& selectedLights() const { return lights_; }
    int currentLight() const { return lights_.empty() ? -1 : lights_.back(); }
    // Drops indices outside the scene and repeats (keeping the order).
    void setSelectedLights(std::vector<int> lights);
    bool cameraSelected() const { return camera_; }
    void selectCamera();
    // Tile of the culling grid selected in the camera view (-1: none).
    int selectedTile() const { return tile_; }
    void setSelectedTile(int tile);
    // Whether the current light was picked after the selected tile (Frame
    // selected then frames the light, unless the tile lists it).
    bool lightSelectedLast() const { return lightLast_; }
    // Depth cell of the selected tile (tileCells order, -1: the whole tile).
    // Emits tileChanged; selecting another tile clears it.
    int selectedCell() const { return cell_; }
    void setSelectedCell(int cell);
    // The list the user picked for Explain (a tile inspector row: halfz and
    // clustered tiles have several), or -1: the panel then takes the tile's
    // first list that holds or needs the current light. Cleared with the tile
    // or cell selection and by a new run (the Document's run tracking).
    int explainedList() const { return explainedList_; }
    void setExplainedList(int list);

    // --- for the Document ------------------------------------------------------
    // Silent: the Document emits this object's signals once the scene and
    // every part agree, so no receiver sees a selection of another scene.
    // Nothing selected (a new scene).
    void reset();
    // The lights after an insertion or removal (indices already valid);
    // `deselectCamera`: the camera stops being selected.
    void replaceLights(std::vector<int> lights, bool deselectCamera);
    // No tile, cell or explained list (the camera, and with it the grid, changed).
    void clearTile();
    // A new run's lists: a picked list index no longer means the same list.
    void forgetExplainedList() {
        explainedList_ = -1;
        ++revision_;
    }

    // Counts every change, announced or silent (what is worked out from the
    // selection is kept while it is the same).
    quint64 revision() const { return revision_; }

signals:
    void changed();          // lights, camera or the explained list
    void tileChanged(int tile); // also when the selected cell changes

private:
    const lc::Scene& scene_;
    std::vector<int> lights_;
    bool camera_ = false;
    int tile_ = -1;
    bool lightLast_ = false;
    int cell_ = -1;
    int explainedList_ = -1;
    quint64 revision_ = 0;
};

} // namespace lcui
