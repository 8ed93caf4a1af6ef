#pragma once
// The inspector view's inspection overlays, built from the document's latest
// run with the culling library's overlay geometry (culling/diagnostics/overlays.hpp):
// - the selected tile's frustum (translucent solid + outline);
// - its depth cells: occupied cells filled, empty ones outlined, the selected
//   cell highlighted; the halfz split as a filled quad; clustered froxels;
// - the cells the current light's sphere spans in that tile (green outline);
//   under zbin also the slab of the whole camera frustum over its Z-bins
//   (translucent green), and the tile's bins as its cells;
// - every tile's frustum as ONE wireframe poly-data actor coloured by list
//   length (interactive at ~8,000 tiles: 12 lines per tile, one draw);
// - reverse look-up: the frustums (halfz/clustered: the cells) whose lists
//   hold the current light, magenta;
// - the selected tile's listed lights highlighted (the light glyph actor is
//   dimmed meanwhile), missing lights in red. They follow View > Lights: as
//   filled spheres up to the sphere cap and as bright silhouette rings above
//   it (Auto) or always (Outlines); as at most sphereCap spheres, the nearest
//   the tile first (Spheres). With only the tile's lights shown the view's own
//   light actor draws them and only the missing ones are added here.
// - the primitive the run's spot test used for the current spot light (View >
//   Overlays > Spot test primitive, off by default; lc::spotTestPrimitive):
//   its culling sphere (apex or tight sphere, pink), and for the selected
//   tile under cone-sphere the bounding sphere of every chunk the cone was
//   tested against, under cone-planes those chunks' outlines (blue: passed,
//   red: rejected), with a caption saying which test and what was tested.
// - Explain in 3D (Document::explained: the selected list and the current
//   light): the chunk plane that decided (red: it rejected the light; violet:
//   every plane kept it and this one came closest to rejecting it), and the
//   pixel that matters: for a false positive the nearest pixel of the list
//   with a white line to the light's sphere (the gap the tests could not
//   see), for a needed light the needing pixel nearest its centre (green).
// Each part follows its OverlayOptions toggle. Translucent parts
// rely on the renderer's depth peeling (set up by InspectorView).

#include "culling/diagnostics/explain.hpp"
#include "culling/diagnostics/overlays.hpp"

#include <vtkNew.h>
#include <vtkSmartPointer.h>

#include <memory>
#include <optional>
#include <vector>

class vtkActor;
class vtkGlyph3D;
class vtkLookupTable;
class vtkPolyData;
class vtkRenderer;
class vtkSphereSource;
class vtkTextActor;

namespace lcui {

class Document;

class InspectorOverlays {
public:
    InspectorOverlays(vtkRenderer* renderer, vtkSphereSource* sphere);
    ~InspectorOverlays();

    // Rebuilds everything that depends on the document's state.
    void update(const Document& doc);
    // Whether the light glyphs should be dimmed (a tile's lists are highlighted).
    bool dimLights() const { return dim_; }
    // The lights in the lists of the document's selected tile (for halfz and
    // clustered with a cell selected: that cell's list), ascending; nullopt
    // without a tile or a run that still describes the scene.
    static std::optional<std::vector<int>> tileListLights(const Document& doc);
    // The highlighted listed lights: drawn as rings (else filled spheres), and
    // how many the sphere cap left out.
    bool listedAsRings() const { return listedRings_; }
    std::size_t listedLeftOut() const { return listedLeftOut_; }
    vtkActor* listedActor() const;

    // --- for tests and screenshots ---------------------------------------------
    vtkPolyData* tileSolid() const;
    vtkPolyData* cellFill() const;    // occupied cells (6 quads each)
    vtkPolyData* cellOutline() const; // every cell (12 lines each)
    vtkPolyData* splitQuad() const;   // halfz split
    vtkPolyData* lightRange() const;  // cells the current light spans
    vtkPolyData* zbinSlab() const;    // zbin: the camera frustum over the current light's bins
    vtkPolyData* allTiles() const;    // every tile frustum, "list_length" cell data
    vtkPolyData* reverse() const;     // volumes whose list holds the current light
    vtkActor* allTilesActor() const;
    const std::vector<int>& listedLights() const { return listed_; }   // highlighted
    const std::vector<int>& missingLights() const { return missing_; } // red
    const std::vector<std::uint32_t>& reverseLists() const { return reverseLists_; }

    // The spot test primitive overlay (OverlayOptions::spotPrimitive): what was drawn last (nullopt: nothing), in view space as the culling has it.
    const std::optional<lc::SpotTestPrimitive>& spotPrimitive() const { return spotPrimitive_; }
    vtkPolyData* spotCullSphere() const;     // 3 great circles, world space
    vtkPolyData* spotChunksPassed() const;   // cone-sphere: circles; cone-planes: chunk edges
    vtkPolyData* spotChunksRejected() const;
    vtkTextActor* spotCaption() const;
    // Explain in 3D (world space): the deciding plane (one quad and its
    // outline: the chunk's face scaled by kExplainPlaneScale about its
    // centre) and the pixel marker (point 0; for a false positive point 1 on
    // the light's sphere, joined by a line).
    static const double kExplainPlaneScale;
    vtkPolyData* explainPlane() const;
    vtkPolyData* explainPixel() const;
    const std::optional<lc::Explanation>& explanation() const { return explanation_; }

private:
    struct Impl;
    std::unique_ptr<Impl> d_;
    bool dim_ = false;
    bool listedRings_ = false;
    std::size_t listedLeftOut_ = 0;
    std::vector<int> listed_, missing_;
    std::vector<std::uint32_t> reverseLists_;
    const void* allTilesRun_ = nullptr; // run the all-tiles wireframe was built for
    std::optional<lc::SpotTestPrimitive> spotPrimitive_;
    std::optional<lc::Explanation> explanation_;
    void updateSpotPrimitive(const Document& doc, const lc::RunOutput* run, int tile);
    void updateExplainMarkers(const Document& doc);
};

} // namespace lcui
