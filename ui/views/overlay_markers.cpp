// The inspector's markers for one light in one list: Explain in 3D (the
// deciding plane, the nearest or needing pixel) and the spot test primitive the
// run evaluated (overlay_actors.hpp).
#include "views/overlay_actors_parts.hpp"

#include "document/document.hpp"

namespace lcui {

using namespace overlay_parts;

const double InspectorOverlays::kExplainPlaneScale = 1.5;

void InspectorOverlays::updateExplainMarkers(const Document& doc) {
    d_->explainPlane->Initialize();
    d_->explainPixel->Initialize();
    explanation_.reset();
    if (doc.viewOptions().overlays().explainMarkers) {
        // On error the Explain panel shows the message; nothing to draw.
        explanation_ = doc.explained().explanation;
    }
    const glm::dmat4 w = lc::worldFromView(doc.scene().camera);
    auto world = [&w](const glm::dvec3& v) {
        const glm::dvec4 p = w * glm::dvec4(v, 1.0);
        return glm::dvec3(p);
    };
    if (explanation_ && explanation_->hasChunk && explanation_->decisivePlane >= 0) {
        const lc::Explanation& e = *explanation_;
        vtkNew<vtkPoints> pts;
        vtkNew<vtkCellArray> polys, lines;
        vtkIdType ids[5];
        // The plane is unbounded: its piece around the chunk's face, half as
        // large again, so that it shows beside the face's cells and edges.
        const auto face = lc::chunkFace(e.chunkCorners, e.decisivePlane);
        const glm::dvec3 mid = 0.25 * (face[0] + face[1] + face[2] + face[3]);
        for (int i = 0; i < 4; ++i) {
            const glm::dvec3 p = world(mid + kExplainPlaneScale * (face[std::size_t(i)] - mid));
            ids[i] = pts->InsertNextPoint(p.x, p.y, p.z);
        }
        ids[4] = ids[0];
        polys->InsertNextCell(4, ids);
        lines->InsertNextCell(5, ids);
        d_->explainPlane->SetPoints(pts);
        d_->explainPlane->SetPolys(polys);
        d_->explainPlane->SetLines(lines);
        for (vtkActor* a : {d_->explainPlaneA.Get(), d_->explainEdgeA.Get()}) {
            if (e.decisiveMargin < 0) a->GetProperty()->SetColor(1.0, 0.15, 0.1);
            else a->GetProperty()->SetColor(0.55, 0.35, 1.0);
        }
    }
    if (explanation_) {
        const lc::Explanation& e = *explanation_;
        vtkNew<vtkPoints> pts;
        vtkNew<vtkCellArray> verts, lines;
        if (e.nearestDistance >= 0) {
            // The nearest pixel of a false positive, and the nearest point of
            // the light's range sphere: the gap the tests did not see.
            const glm::dvec3 p = world(e.nearestPosition);
            const auto& lights = doc.runs().runOutput()->lights;
            const glm::dvec3 c = lights.centers[e.light];
            const glm::dvec3 dir = e.nearestPosition - c;
            const double len = glm::length(dir);
            const glm::dvec3 q = world(len > 0 ? c + dir * (lights.radii[e.light] / len) : c);
            const vtkIdType a = pts->InsertNextPoint(p.x, p.y, p.z);
            const vtkIdType b = pts->InsertNextPoint(q.x, q.y, q.z);
            verts->InsertNextCell(1, &a);
            const vtkIdType seg[2] = {a, b};
            lines->InsertNextCell(2, seg);
            d_->explainPixelA->GetProperty()->SetColor(1.0, 1.0, 1.0);
        } else if (e.hasNeededPixel) {
            const glm::dvec3 p = world(e.neededPosition);
            const vtkIdType a = pts->InsertNextPoint(p.x, p.y, p.z);
            verts->InsertNextCell(1, &a);
            d_->explainPixelA->GetProperty()->SetColor(0.2, 1.0, 0.3);
        }
        d_->explainPixel->SetPoints(pts);
        if (verts->GetNumberOfCells()) d_->explainPixel->SetVerts(verts);
        if (lines->GetNumberOfCells()) d_->explainPixel->SetLines(lines);
    }
    d_->explainPlaneA->SetVisibility(d_->explainPlane->GetNumberOfCells() > 0);
    d_->explainEdgeA->SetVisibility(d_->explainPlane->GetNumberOfCells() > 0);
    d_->explainPixelA->SetVisibility(d_->explainPixel->GetNumberOfCells() > 0);
}

void InspectorOverlays::updateSpotPrimitive(const Document& doc, const lc::RunOutput* run, int tile) {
    for (vtkPolyData* pd : {d_->spotSphere.Get(), d_->spotPassed.Get(), d_->spotRejected.Get()}) pd->Initialize();
    spotPrimitive_.reset();
    const int light = doc.selection().currentLight();
    // The run's own light (what was culled), not the scene's current one.
    if (doc.viewOptions().overlays().spotPrimitive && run && light >= 0 && std::size_t(light) < run->lights.size()) {
        const lc::Camera& cam = doc.scene().camera;
        spotPrimitive_ = lc::spotTestPrimitive(*run, lc::Projection(cam), std::uint32_t(light), tile);
    }
    QString caption;
    if (spotPrimitive_) {
        const lc::SpotTestPrimitive& p = *spotPrimitive_;
        const glm::dmat4 w = lc::worldFromView(doc.scene().camera);
        {
            vtkNew<vtkPoints> pts;
            vtkNew<vtkCellArray> lines;
            addSphereCircles(pts, lines, w, p.cullSphere);
            d_->spotSphere->SetPoints(pts);
            d_->spotSphere->SetLines(lines);
        }
        ChunkGeometry passedEdges, rejectedEdges;
        passedEdges.worldFromView = rejectedEdges.worldFromView = w;
        vtkNew<vtkPoints> passedPts, rejectedPts;
        vtkNew<vtkCellArray> passedLines, rejectedLines;
        std::size_t passed = 0;
        for (const lc::SpotTestChunk& c : p.chunks) {
            passed += c.passed;
            if (p.test == lc::SpotTest::ConeSphere)
                addSphereCircles(c.passed ? passedPts : rejectedPts, c.passed ? passedLines : rejectedLines, w,
                                 c.sphere, 32);
            else if (p.test == lc::SpotTest::ConePlanes)
                (c.passed ? passedEdges : rejectedEdges).edges(c.chunk);
        }
        if (p.test == lc::SpotTest::ConeSphere) {
            for (auto [pd, pts, lines] : {std::tuple{d_->spotPassed.Get(), passedPts.Get(), passedLines.Get()},
                                          std::tuple{d_->spotRejected.Get(), rejectedPts.Get(), rejectedLines.Get()}}) {
                pd->SetPoints(pts);
                if (lines->GetNumberOfCells()) pd->SetLines(lines);
            }
        } else if (p.test == lc::SpotTest::ConePlanes) {
            passedEdges.into(d_->spotPassed);
            rejectedEdges.into(d_->spotRejected);
        }
        const QString sphere = p.test == lc::SpotTest::ApexSphere ? QObject::tr("apex sphere") : QObject::tr("tight sphere");
        // Short lines: the inspector is often a narrow dock.
        caption = QObject::tr("spot test %1, light %2\n%3 r=%4 (pink)")
                      .arg(lc::toString(p.test))
                      .arg(light)
                      .arg(sphere)
                      .arg(p.cullSphere.radius, 0, 'g', 4);
        const QString verdict = QObject::tr("%1 passed (blue), %2 rejected (red)")
                                    .arg(passed)
                                    .arg(p.chunks.size() - passed);
        if (tile < 0)
            caption += QObject::tr("\nselect a tile to see its chunks");
        else if (p.chunks.empty())
            caption += QObject::tr("\ntile %1: not tested (no geometry or\nno chunk in the sphere's depth range)").arg(tile);
        else if (p.test == lc::SpotTest::ConeSphere)
            caption += QObject::tr("\ntile %1: cone vs each chunk's bounding sphere\n%2").arg(tile).arg(verdict);
        else if (p.test == lc::SpotTest::ConePlanes)
            caption += QObject::tr("\ntile %1: cone vs the 6 planes of each chunk\n%2").arg(tile).arg(verdict);
        else
            caption += QObject::tr("\ntile %1: sphere vs the tile's chunks\n%2").arg(tile).arg(verdict);
    }
    d_->spotCaption->SetInput(caption.toUtf8().constData());
    d_->spotCaption->SetVisibility(!caption.isEmpty());
    d_->spotSphereA->SetVisibility(d_->spotSphere->GetNumberOfCells() > 0);
    d_->spotPassedA->SetVisibility(d_->spotPassed->GetNumberOfCells() > 0);
    d_->spotRejectedA->SetVisibility(d_->spotRejected->GetNumberOfCells() > 0);
}

} // namespace lcui
