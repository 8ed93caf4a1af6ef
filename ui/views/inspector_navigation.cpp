// The inspector view's camera: reset, frame the selection (from the culling
// camera's side when meshes would hide it), fly and look through the culling
// camera (inspector_view.hpp).
#include "views/inspector_view.hpp"

#include "document/document.hpp"
#include "views/light_silhouettes.hpp"
#include "views/overlay_actors.hpp"
#include "views/vtk_adapters.hpp"
#include "views/spot_actor.hpp"
#include "views/spot_handles.hpp"

#include "culling/math/projection.hpp"

#include <QStringList>
#include <QTimer>

#include "culling/diagnostics/overlays.hpp"

#include <functional>
#include <optional>
#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkCameraPass.h>
#include <vtkCellArray.h>
#include <vtkCellPicker.h>
#include <vtkDataArray.h>
#include <vtkGenericOpenGLRenderWindow.h>
#include <vtkGlyph3D.h>
#include <vtkHandleWidget.h>
#include <vtkInteractorStyleTrackballCamera.h>
#include <vtkLightsPass.h>
#include <vtkOpaquePass.h>
#include <vtkOverlayPass.h>
#include <vtkPointData.h>
#include <vtkPointHandleRepresentation3D.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRenderPassCollection.h>
#include <vtkRenderer.h>
#include <vtkSequencePass.h>
#include <vtkSphereSource.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkTranslucentPass.h>
#include <vtkVolumetricPass.h>
#include <QVTKInteractor.h>

#include <algorithm>
#include <cmath>
#include <numeric>

namespace lcui {

void InspectorView::resetCamera() {
    // Frame the meshes (not every light sphere: a generated cloud can be far
    // larger than the scene) from above and to the side of the culling camera.
    auto [lo, hi] = doc_->scene().bounds();
    // A scene without meshes (a RenderDoc capture's lights): frame the
    // lights' centres and the camera.
    if (doc_->scene().meshes.empty() && !doc_->scene().lights.empty()) {
        lo = hi = doc_->scene().camera.position;
        for (const lc::PointLight& l : doc_->scene().lights) {
            lo = glm::min(lo, l.position);
            hi = glm::max(hi, l.position);
        }
    }
    const lc::Camera& c = doc_->scene().camera;
    glm::dvec3 center = 0.5 * (lo + hi);
    double diag = glm::length(hi - lo);
    if (diag <= 0) {
        center = c.target;
        diag = std::max(1.0, glm::length(c.target - c.position));
    }
    glm::dvec3 dir = c.position - c.target;
    if (glm::length(dir) < 1e-9) dir = {0, 0, 1};
    dir = glm::normalize(dir);
    const glm::dvec3 up = glm::normalize(c.up);
    // Rotate 35 degrees around up and lift: the frustum is seen from outside.
    const glm::dvec3 side = glm::normalize(glm::cross(up, dir));
    glm::dvec3 eyeDir = glm::normalize(std::cos(0.6) * dir + std::sin(0.6) * side + 0.55 * up);
    vtkCamera* vc = renderer_->GetActiveCamera();
    vc->SetFocalPoint(center.x, center.y, center.z);
    const glm::dvec3 eye = center + eyeDir * diag;
    vc->SetPosition(eye.x, eye.y, eye.z);
    vc->SetViewUp(up.x, up.y, up.z);
    vc->SetViewAngle(30);
    vc->ParallelProjectionOff();
    // Keep the direction, move back until the scene and the culling camera's
    // eye (the apex of the frustum) fit.
    if (glm::length(hi - lo) > 0) {
        const glm::dvec3 blo = glm::min(lo, c.position), bhi = glm::max(hi, c.position);
        double b[6] = {blo.x, bhi.x, blo.y, bhi.y, blo.z, bhi.z};
        renderer_->ResetCamera(b);
        vc->Zoom(1.15); // ResetCamera frames the bounding sphere, which leaves a wide margin
    }
    renderer_->ResetCameraClippingRange();
    cameraFramed_ = true;
    renderNow();
}

std::pair<glm::dvec3, glm::dvec3> InspectorView::viewRay(const QPoint& pos) const {
    const double dpr = devicePixelRatioF();
    const double x = pos.x() * dpr, y = (height() - 1 - pos.y()) * dpr;
    auto worldAt = [&](double z) {
        renderer_->SetDisplayPoint(x, y, z);
        renderer_->DisplayToWorld();
        double w[4];
        renderer_->GetWorldPoint(w);
        return glm::dvec3(w[0], w[1], w[2]) / (w[3] != 0.0 ? w[3] : 1.0);
    };
    return {worldAt(0.0), worldAt(1.0)};
}

bool InspectorView::frameSelected(int ms) {
    // What to frame (world points, for the view basis they are seen in), the
    // point to look from the culling camera's side at, and the points whose
    // view must not be blocked: the chunk's near face centre and corners (the
    // tile's nearest geometry lies on that face, and the culling camera sees
    // them), or the light's centre and four points halfway to its sphere.
    std::function<std::vector<glm::dvec3>(const ViewBasis&)> pointsFor;
    std::function<std::vector<glm::dvec3>(const ViewBasis&)> samplesFor;
    glm::dvec3 anchor(0.0);
    double keepOutside = 0; // a light's radius: an eye inside its sphere sees only its wireframe
    frameNote_.clear();
    const auto run = doc_->runs().runOutput();
    const int tile = doc_->selection().selectedTile();
    // A light picked after the tile (the scene tree, a click in 3D) is what
    // the user looks at now, unless the tile lists it (Explain's question:
    // the tile's framing then takes in the light's nearest point).
    bool lightFirst = false;
    if (run && doc_->selection().lightSelectedLast() && doc_->selection().currentLight() >= 0 && tile >= 0 &&
        std::uint32_t(tile) < run->result.grid.tileCount()) {
        const auto held = lc::tilesHoldingLight(run->result, std::uint32_t(doc_->selection().currentLight()));
        lightFirst = std::find(held.begin(), held.end(), std::uint32_t(tile)) == held.end();
    }
    if (!lightFirst && run && tile >= 0 && std::uint32_t(tile) < run->result.grid.tileCount()) {
        const lc::Projection proj(doc_->scene().camera);
        std::optional<lc::FrustumChunk> chunk;
        const int cell = doc_->selection().selectedCell();
        if (cell >= 0)
            for (const lc::DepthCell& c : lc::tileCells(run->result, proj, std::uint32_t(tile)))
                if (int(c.cell) == cell) chunk = c.chunk;
        if (!chunk) chunk = lc::tileFrustum(run->result, proj, run->lights, std::uint32_t(tile));
        if (chunk) {
            const glm::dmat4 world = lc::worldFromView(doc_->scene().camera);
            std::vector<glm::dvec3> corners;
            for (const glm::dvec3& v : chunk->corners) corners.push_back(glm::dvec3(world * glm::dvec4(v, 1.0)));
            anchor = 0.25 * (corners[0] + corners[1] + corners[2] + corners[3]);
            // Pulled a little towards the face's centre: a corner can touch a wall.
            const std::vector<glm::dvec3> samples = {anchor, glm::mix(anchor, corners[0], 0.9), glm::mix(anchor, corners[1], 0.9),
                                                     glm::mix(anchor, corners[2], 0.9), glm::mix(anchor, corners[3], 0.9)};
            samplesFor = [samples](const ViewBasis&) { return samples; };
            // With Explain's markers shown: the pixel that matters (and the
            // nearest point of the light's sphere) come into view too.
            vtkPolyData* marker = overlays_->explainPixel();
            for (vtkIdType i = 0; marker->GetNumberOfCells() > 0 && i < marker->GetNumberOfPoints(); ++i) {
                double p[3];
                marker->GetPoint(i, p);
                corners.push_back({p[0], p[1], p[2]});
            }
            pointsFor = [corners](const ViewBasis&) { return corners; };
        }
    }
    const int light = doc_->selection().currentLight();
    if (!pointsFor && light >= 0 && std::size_t(light) < doc_->scene().lights.size()) {
        const lc::PointLight& l = doc_->scene().lights[std::size_t(light)];
        const glm::dvec3 c = l.position;
        const double r = std::max(l.radius(), 1e-3);
        anchor = c;
        keepOutside = r;
        // The sphere's six extreme points along the view axes bound it well enough.
        pointsFor = [c, r](const ViewBasis& b) {
            return std::vector<glm::dvec3>{c + r * b.right, c - r * b.right, c + r * b.up,
                                           c - r * b.up,    c + r * b.dir,   c - r * b.dir};
        };
        samplesFor = [c, r](const ViewBasis& b) {
            const double h = 0.5 * r;
            return std::vector<glm::dvec3>{c, c + h * b.right, c - h * b.right, c + h * b.up, c - h * b.up};
        };
    }
    if (!pointsFor) return false;

    framedFromCullingSide_ = false;
    const ViewBasis b = viewBasis();
    glm::dvec3 center;
    const double distance = fitDistance(pointsFor(b), b, &center);
    const glm::dvec3 eye = center - b.dir * distance;
    const lc::Scene& scene = doc_->scene();
    // The kept direction works unless shown meshes stand between the eye and
    // most of the selection (the roof of a building framed from outside; a
    // block hiding a corner of a tile is no reason to turn). Nearly at a
    // sample does not count: that is the selection's own surface.
    const bool meshesShown = doc_->viewOptions().overlays().meshes != OverlayOptions::MeshDisplay::Hidden;
    auto blocked = [&](const glm::dvec3& from) {
        const std::vector<glm::dvec3> samples = samplesFor(b);
        std::size_t hidden = 0;
        for (const glm::dvec3& p : samples) {
            const auto hit = firstMeshHit(scene, from, p);
            hidden += hit && *hit < 1.0 - 1e-3;
        }
        return 2 * hidden > samples.size();
    };
    if (!meshesShown || !blocked(eye)) {
        flyToEye(eye, center, std::nullopt, ms);
        return true;
    }
    // From the culling camera's side: along the line from its eye through the
    // anchor (orthographic: along its direction). The culling camera sees the
    // tile's geometry, so that line is free up to the anchor's depth.
    const lc::Camera& cam = scene.camera;
    glm::dvec3 dir = anchor - cam.position;
    if (lc::isOrthographic(cam.projection) || glm::length(dir) < 1e-9) dir = cam.target - cam.position;
    if (glm::length(dir) < 1e-12) dir = b.dir;
    ViewBasis cb;
    cb.dir = glm::normalize(dir);
    cb.right = glm::cross(cb.dir, glm::normalize(cam.up));
    if (glm::length(cb.right) < 1e-9) cb.right = glm::cross(cb.dir, b.up);
    if (glm::length(cb.right) < 1e-9) cb.right = b.right;
    cb.right = glm::normalize(cb.right);
    cb.up = glm::cross(cb.right, cb.dir);
    glm::dvec3 sideCenter;
    const double sideDistance = fitDistance(pointsFor(cb), cb, &sideCenter);
    // The eye on the line through the anchor (the fit's centre lies near it),
    // pulled in to just before the first surface between them.
    glm::dvec3 sideEye = anchor - cb.dir * (sideDistance + glm::dot(anchor - sideCenter, cb.dir));
    const glm::dvec3 back = sideEye - anchor;
    const glm::dvec3 start = anchor + 1e-3 * back;
    if (const auto hit = firstMeshHit(scene, start, sideEye)) {
        const double along = glm::length(sideEye - start) * *hit;
        const glm::dvec3 pulled = start + glm::normalize(back) * (0.9 * along);
        if (glm::length(pulled - anchor) > keepOutside) {
            sideEye = pulled;
        } else {
            // The room is smaller than the light's sphere: an eye pulled in
            // to the wall would sit inside it and see a wall of wireframe.
            // Frame the whole sphere through the wall, with the meshes in
            // x-ray so that the wall hides nothing.
            OverlayOptions o = doc_->viewOptions().overlays();
            if (o.meshes == OverlayOptions::MeshDisplay::Normal) {
                o.meshes = OverlayOptions::MeshDisplay::XRay;
                doc_->viewOptions().setOverlays(o);
                frameNote_ = tr("Walls stand closer to the light than its radius: meshes in x-ray (X toggles)");
            }
        }
    }
    cb.eye = sideEye;
    framedFromCullingSide_ = true;
    flyToEye(sideEye, anchor + cb.dir * std::max(glm::dot(sideCenter - anchor, cb.dir), 0.0), cb.up, ms);
    return true;
}

std::optional<double> InspectorView::firstMeshHit(const lc::Scene& scene, const glm::dvec3& a, const glm::dvec3& b) {
    // Moller-Trumbore against every triangle; a few rays per F, so no
    // acceleration structure (a 260k-triangle glTF takes milliseconds).
    const glm::dvec3 d = b - a;
    double best = 2.0;
    for (const lc::Mesh& m : scene.meshes) {
        const bool identity = m.transform == glm::dmat4(1.0);
        auto vert = [&](std::uint32_t i) {
            const glm::dvec3 v(m.vertex(i));
            return identity ? v : glm::dvec3(m.transform * glm::dvec4(v, 1.0));
        };
        for (std::size_t t = 0; t + 2 < m.indices.size(); t += 3) {
            if (m.indices[t] >= m.vertexCount() || m.indices[t + 1] >= m.vertexCount() ||
                m.indices[t + 2] >= m.vertexCount())
                continue;
            const glm::dvec3 v0 = vert(m.indices[t]), e1 = vert(m.indices[t + 1]) - v0, e2 = vert(m.indices[t + 2]) - v0;
            const glm::dvec3 p = glm::cross(d, e2);
            const double det = glm::dot(e1, p);
            if (std::abs(det) < 1e-300) continue;
            const double inv = 1.0 / det;
            const glm::dvec3 s = a - v0;
            const double u = glm::dot(s, p) * inv;
            if (u < 0.0 || u > 1.0) continue;
            const glm::dvec3 q = glm::cross(s, e1);
            const double v = glm::dot(d, q) * inv;
            if (v < 0.0 || u + v > 1.0) continue;
            const double h = glm::dot(e2, q) * inv;
            if (h >= 0.0 && h <= 1.0 && h < best) best = h;
        }
    }
    if (best > 1.0) return std::nullopt;
    return best;
}

void InspectorView::flyTo(const glm::dvec3& center, double radius, int ms) {
    // The sphere's six extreme points along the view axes bound it well enough.
    const ViewBasis b = viewBasis();
    flyToPoints({center + radius * b.right, center - radius * b.right, center + radius * b.up, center - radius * b.up,
                 center + radius * b.dir, center - radius * b.dir},
                ms);
}

InspectorView::ViewBasis InspectorView::viewBasis() const {
    vtkCamera* vc = renderer_->GetActiveCamera();
    double p0[3], f0[3], vu[3];
    vc->GetPosition(p0);
    vc->GetFocalPoint(f0);
    vc->GetViewUp(vu);
    ViewBasis b;
    b.eye = {p0[0], p0[1], p0[2]};
    b.focal = {f0[0], f0[1], f0[2]};
    b.dir = b.focal - b.eye;
    if (glm::length(b.dir) < 1e-12) b.dir = {0, 0, -1};
    b.dir = glm::normalize(b.dir);
    b.right = glm::cross(b.dir, glm::dvec3(vu[0], vu[1], vu[2]));
    if (glm::length(b.right) < 1e-12) b.right = glm::dvec3(1, 0, 0);
    b.right = glm::normalize(b.right);
    b.up = glm::cross(b.right, b.dir);
    return b;
}

double InspectorView::fitDistance(const std::vector<glm::dvec3>& points, const ViewBasis& b, glm::dvec3* centerOut) {
    vtkCamera* vc = renderer_->GetActiveCamera();
    glm::dvec3 center(0.0);
    for (const glm::dvec3& p : points) center += p;
    center /= double(std::max<std::size_t>(points.size(), 1));
    // The nearest eye distance from `center` at which every point projects
    // inside the view, with a 10% margin: x / (d + z) <= tan.
    const double halfY = 0.5 * vc->GetViewAngle() * 3.14159265358979323846 / 180.0;
    const double aspect = height() > 0 ? double(width()) / double(height()) : 1.0;
    const double tanY = std::tan(halfY) / 1.1, tanX = std::tan(halfY) * aspect / 1.1;
    double distance = 1e-6, extentX = 1e-6, extentY = 1e-6;
    for (const glm::dvec3& p : points) {
        const glm::dvec3 q = p - center;
        const double x = std::abs(glm::dot(q, b.right)), y = std::abs(glm::dot(q, b.up)), z = glm::dot(q, b.dir);
        distance = std::max({distance, x / tanX - z, y / tanY - z});
        extentX = std::max(extentX, x);
        extentY = std::max(extentY, y);
    }
    if (vc->GetParallelProjection()) vc->SetParallelScale(1.1 * std::max(extentY, extentX / aspect));
    *centerOut = center;
    return distance;
}

void InspectorView::flyToPoints(const std::vector<glm::dvec3>& points, int ms) {
    if (points.empty()) return;
    // Keep the direction.
    const ViewBasis b = viewBasis();
    glm::dvec3 center;
    const double distance = fitDistance(points, b, &center);
    flyToEye(center - b.dir * distance, center, std::nullopt, ms);
}

void InspectorView::flyToEye(const glm::dvec3& toEye, const glm::dvec3& toFocal, std::optional<glm::dvec3> toUp,
                             int ms) {
    vtkCamera* vc = renderer_->GetActiveCamera();
    const ViewBasis b = viewBasis();
    const glm::dvec3 fromEye = b.eye, fromFocal = b.focal, fromUp = b.up;
    const int steps = std::max(1, ms / 25);
    auto apply = [this, vc, fromEye, fromFocal, fromUp, toEye, toFocal, toUp](double t) {
        const double s = t * t * (3.0 - 2.0 * t); // ease in and out
        const glm::dvec3 e = glm::mix(fromEye, toEye, s), f = glm::mix(fromFocal, toFocal, s);
        vc->SetFocalPoint(f.x, f.y, f.z);
        vc->SetPosition(e.x, e.y, e.z);
        // The view up is left alone when the direction is kept (an orbit
        // turns about it).
        if (toUp) {
            glm::dvec3 u = glm::mix(fromUp, *toUp, s);
            if (glm::length(u) < 1e-9) u = *toUp;
            vc->SetViewUp(u.x, u.y, u.z);
            vc->OrthogonalizeViewUp();
        }
        renderer_->ResetCameraClippingRange();
        placeRadiusHandle();
        spotHandles_->update();
        renderNow();
    };
    if (ms <= 0) {
        ++flight_; // stops a flight in progress
        apply(1.0);
        return;
    }
    ++flight_;
    const int flight = flight_;
    for (int i = 1; i <= steps; ++i)
        QTimer::singleShot(i * ms / steps, this, [apply, i, steps, flight, this] {
            if (flight == flight_) apply(double(i) / steps); // a newer flight takes over
        });
}

void InspectorView::lookThroughCullingCamera() {
    ++flight_; // stops a flight in progress
    const lc::Camera& c = doc_->scene().camera;
    applyCullingCamera(renderer_->GetActiveCamera(), c);
    renderer_->ResetCameraClippingRange();
    renderNow();
}

} // namespace lcui
