#pragma once
// What overlay_actors.cpp and overlay_markers.cpp share: InspectorOverlays'
// VTK data and actors (its Impl) and the geometry helpers both build with.
// Private to those two files.

#include "views/overlay_actors.hpp"

#include "document/document.hpp"
#include "views/light_silhouettes.hpp"
#include "views/vtk_adapters.hpp"

#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkDoubleArray.h>
#include <vtkGlyph3D.h>
#include <vtkLookupTable.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderer.h>
#include <vtkSphereSource.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>

#include <glm/gtc/constants.hpp>

#include <QObject>
#include <QString>

#include <algorithm>
#include <cmath>
#include <tuple>

namespace lcui {

namespace overlay_parts {

// Accumulates world-space chunk geometry into one poly data.
struct ChunkGeometry {
    vtkNew<vtkPoints> points;
    vtkNew<vtkCellArray> lines, polys;
    glm::dmat4 worldFromView{1.0};

    vtkIdType corner(const glm::dvec3& v) {
        const glm::dvec4 w = worldFromView * glm::dvec4(v, 1.0);
        return points->InsertNextPoint(w.x, w.y, w.z);
    }
    // corners: near tl,tr,br,bl; far tl,tr,br,bl
    void faces(const lc::FrustumChunk& c) {
        vtkIdType id[8];
        for (int i = 0; i < 8; ++i) id[i] = corner(c.corners[i]);
        const int f[6][4] = {{0, 1, 2, 3}, {4, 7, 6, 5}, {0, 3, 7, 4}, {1, 5, 6, 2}, {0, 4, 5, 1}, {3, 2, 6, 7}};
        for (const auto& q : f) {
            const vtkIdType ids[4] = {id[q[0]], id[q[1]], id[q[2]], id[q[3]]};
            polys->InsertNextCell(4, ids);
        }
    }
    void edges(const lc::FrustumChunk& c) {
        vtkIdType id[8];
        for (int i = 0; i < 8; ++i) id[i] = corner(c.corners[i]);
        static constexpr int e[12][2] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6},
                                         {6, 7}, {7, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
        for (const auto& k : e) {
            const vtkIdType ids[2] = {id[k[0]], id[k[1]]};
            lines->InsertNextCell(2, ids);
        }
    }
    // The near face of a chunk only (the halfz split of the far half).
    void nearFace(const lc::FrustumChunk& c) {
        vtkIdType id[4];
        for (int i = 0; i < 4; ++i) id[i] = corner(c.corners[i]);
        polys->InsertNextCell(4, id);
    }
    void into(vtkPolyData* pd) {
        pd->Initialize();
        pd->SetPoints(points);
        if (lines->GetNumberOfCells()) pd->SetLines(lines);
        if (polys->GetNumberOfCells()) pd->SetPolys(polys);
    }
};

// A sphere as three orthogonal great circles (view-space centre, world
// lines): light enough for dozens of cells, and every point lies on it.
inline void addSphereCircles(vtkPoints* points, vtkCellArray* lines, const glm::dmat4& worldFromView,
                      const lc::BoundingSphere& s, int segments = 48) {
    const glm::dvec3 axes[3][2] = {{{1, 0, 0}, {0, 1, 0}}, {{0, 1, 0}, {0, 0, 1}}, {{0, 0, 1}, {1, 0, 0}}};
    for (const auto& e : axes) {
        std::vector<vtkIdType> ids;
        for (int i = 0; i <= segments; ++i) {
            const double t = 2.0 * glm::pi<double>() * (i % segments) / segments;
            const glm::dvec3 v = s.center + s.radius * (std::cos(t) * e[0] + std::sin(t) * e[1]);
            const glm::dvec4 w = worldFromView * glm::dvec4(v, 1.0);
            ids.push_back(points->InsertNextPoint(w.x, w.y, w.z));
        }
        lines->InsertNextCell(vtkIdType(ids.size()), ids.data());
    }
}

inline vtkSmartPointer<vtkActor> makeActor(vtkPolyData* pd, double r, double g, double b, double opacity,
                                    double lineWidth = 1.0) {
    vtkNew<vtkPolyDataMapper> m;
    m->SetInputData(pd);
    m->ScalarVisibilityOff();
    auto a = vtkSmartPointer<vtkActor>::New();
    a->SetMapper(m);
    a->GetProperty()->SetColor(r, g, b);
    a->GetProperty()->SetOpacity(opacity);
    a->GetProperty()->SetLineWidth(lineWidth);
    a->GetProperty()->SetLighting(false);
    a->PickableOff();
    return a;
}

} // namespace overlay_parts

struct InspectorOverlays::Impl {
    vtkRenderer* renderer;
    vtkNew<vtkPolyData> spotSphere, spotPassed, spotRejected;
    vtkSmartPointer<vtkActor> spotSphereA, spotPassedA, spotRejectedA;
    vtkNew<vtkTextActor> spotCaption;
    vtkNew<vtkPolyData> explainPlane, explainPixel, zbinSlab;
    vtkSmartPointer<vtkActor> zbinSlabA;
    vtkSmartPointer<vtkActor> explainPlaneA, explainEdgeA, explainPixelA;
    vtkNew<vtkPolyData> tileSolid, tileOutline, cellFill, cellOutline, cellSelected, splitQuad, lightRange,
        allTiles, reverse;
    vtkSmartPointer<vtkActor> tileSolidA, tileOutlineA, cellFillA, cellOutlineA, cellSelectedA, splitA, rangeA,
        allTilesA, reverseA;
    vtkNew<vtkLookupTable> lut;
    vtkSmartPointer<vtkPolyData> listedData, missingData;
    vtkNew<vtkGlyph3D> listedGlyph, missingGlyph;
    vtkNew<vtkActor> listedA, missingA;
    // The listed lights as silhouette rings (many of them, or View > Lights > Outlines).
    vtkNew<LightSilhouettes> listedRings;
    vtkSmartPointer<vtkMapper> listedGlyphMapper;
    vtkNew<vtkPolyDataMapper> listedRingMapper;
};

} // namespace lcui
