#pragma once
// How the views show the document: the inspection overlays and how meshes and
// lights are drawn. View state, not part of the scene and not undoable; one
// place for it, so a view never keeps its own copy to refresh by hand.

#include "culling/diagnostics/overlays.hpp"

#include <QObject>

namespace lcui {

struct OverlayOptions {
    bool tileFrustum = true;      // the selected tile's frustum, translucent + outline
    bool allTileFrustums = false; // every tile's frustum, one wireframe by list length
    bool cells = true;            // 2.5d cells, halfz split, clustered froxels
    bool lightCellRange = true;   // cells the current light's sphere spans
    bool listHighlight = true;    // listed lights highlighted, others dimmed, missing red
    bool reverseLookup = true;    // tiles whose lists hold the current light
    bool explainMarkers = true;   // Explain in 3D: the deciding plane, the nearest or needing pixel
    // The inspector's spot lights drawn as the primitive the culling tests
    // (the apex sphere or the cone's bounding sphere) instead of the cone.
    bool spotPrimitive = false;
    lc::HeatMode heat = lc::HeatMode::ListLength;
    // The inspector inside a building (View > Meshes, View > Lights; docs/STUDIO.md):
    // meshes drawn as they are, translucent without depth writes (x-ray:
    // they hide and block nothing), or not at all.
    enum class MeshDisplay { Normal, XRay, Hidden };
    MeshDisplay meshes = MeshDisplay::Normal;
    // Lights: filled spheres up to sphereCap and silhouette rings above it
    // (Auto), spheres only (at most sphereCap, "+N more" for the rest), or
    // rings only. showLights hides them and the spot cones together;
    // onlyTileLights draws only the selected tile's (cell's) listed lights.
    enum class LightDisplay { Auto, Spheres, Outlines };
    LightDisplay lights = LightDisplay::Auto;
    bool showLights = true;
    bool onlyTileLights = false;
    int sphereCap = 256;
    bool operator==(const OverlayOptions&) const = default;
};

class ViewOptions : public QObject {
    Q_OBJECT
public:
    using QObject::QObject;
    const OverlayOptions& overlays() const { return overlays_; }
    void setOverlays(const OverlayOptions& o) {
        if (o == overlays_) return;
        overlays_ = o;
        emit overlaysChanged();
    }

signals:
    void overlaysChanged();

private:
    OverlayOptions overlays_;
};

} // namespace lcui
