#include "views/light_silhouettes.hpp"

#include <array>
#include <cmath>
#include <glm/glm.hpp>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkDataArray.h>
#include <vtkFloatArray.h>
#include <vtkIdTypeArray.h>
#include <vtkInformation.h>
#include <vtkInformationVector.h>
#include <vtkObjectFactory.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkUnsignedCharArray.h>

namespace lcui {

vtkStandardNewMacro(LightSilhouettes);

LightSilhouettes::LightSilhouettes() = default;
LightSilhouettes::~LightSilhouettes() = default;

void LightSilhouettes::SetCamera(vtkCamera* camera) {
    if (camera_.Get() == camera) return;
    camera_ = camera;
    Modified();
}

vtkMTimeType LightSilhouettes::GetMTime() {
    vtkMTimeType t = Superclass::GetMTime();
    if (camera_) t = std::max(t, camera_->GetMTime());
    return t;
}

int LightSilhouettes::RequestData(vtkInformation*, vtkInformationVector** inputVector,
                                  vtkInformationVector* outputVector) {
    vtkPolyData* in = vtkPolyData::GetData(inputVector[0]);
    vtkPolyData* out = vtkPolyData::GetData(outputVector);
    if (!in || !out) return 0;
    const vtkIdType n = in->GetNumberOfPoints();
    vtkDataArray* radius = in->GetPointData()->GetArray("radius");
    vtkDataArray* color = in->GetPointData()->GetArray("color");
    if (n > 0 && (!radius || !camera_)) {
        vtkErrorMacro("LightSilhouettes needs a \"radius\" array and a camera");
        return 0;
    }
    constexpr int S = kSegments;
    std::array<double, S> cs{}, sn{};
    for (int k = 0; k < S; ++k) {
        cs[std::size_t(k)] = std::cos(2.0 * M_PI * k / S);
        sn[std::size_t(k)] = std::sin(2.0 * M_PI * k / S);
    }
    glm::dvec3 eye(0.0), dop(0, 0, -1), up(0, 1, 0);
    bool parallel = false;
    if (camera_) {
        double e[3], d[3], u[3];
        camera_->GetPosition(e);
        camera_->GetDirectionOfProjection(d);
        camera_->GetViewUp(u);
        eye = {e[0], e[1], e[2]};
        dop = {d[0], d[1], d[2]};
        up = {u[0], u[1], u[2]};
        parallel = camera_->GetParallelProjection() != 0;
    }

    auto pts = vtkSmartPointer<vtkPoints>::New();
    pts->SetDataTypeToFloat(); // display only: floats halve the upload
    pts->SetNumberOfPoints(n * (S + 1));
    auto* p = static_cast<vtkFloatArray*>(pts->GetData())->GetPointer(0);
    auto rgb = vtkSmartPointer<vtkUnsignedCharArray>::New();
    rgb->SetName("color");
    rgb->SetNumberOfComponents(3);
    rgb->SetNumberOfTuples(n * (S + 1));
    unsigned char* c = rgb->GetPointer(0);

    // Lines: n loops of S + 1 ids (closed); verts: one poly-vertex of n ids.
    auto lineOffsets = vtkSmartPointer<vtkIdTypeArray>::New();
    auto lineConn = vtkSmartPointer<vtkIdTypeArray>::New();
    lineOffsets->SetNumberOfValues(n + 1);
    lineConn->SetNumberOfValues(n * (S + 1));
    vtkIdType* lo = lineOffsets->GetPointer(0);
    vtkIdType* lc = lineConn->GetPointer(0);
    auto vertOffsets = vtkSmartPointer<vtkIdTypeArray>::New();
    auto vertConn = vtkSmartPointer<vtkIdTypeArray>::New();
    vertOffsets->SetNumberOfValues(n > 0 ? 2 : 1);
    vertConn->SetNumberOfValues(n);
    vertOffsets->SetValue(0, 0);
    if (n > 0) vertOffsets->SetValue(1, n);

    for (vtkIdType i = 0; i < n; ++i) {
        double q[3];
        in->GetPoint(i, q);
        const glm::dvec3 centre(q[0], q[1], q[2]);
        const double r = std::max(0.0, radius->GetTuple1(i));
        // The circle of tangency of the cone from the eye to the sphere:
        // normal along eye->centre, pulled towards the eye by r^2/d, radius
        // r*sqrt(d^2-r^2)/d. Parallel projection, or the eye inside the
        // sphere (no outline exists): the great circle facing the view.
        glm::dvec3 normal = dop, ringCentre = centre;
        double ringRadius = r;
        const glm::dvec3 v = centre - eye;
        const double d = glm::length(v);
        if (!parallel && d > r && d > 0) {
            normal = v / d;
            ringCentre = centre - normal * (r * r / d);
            ringRadius = r * std::sqrt(d * d - r * r) / d;
        }
        glm::dvec3 a = glm::cross(normal, up);
        if (glm::length(a) < 1e-9) a = glm::cross(normal, glm::dvec3(1, 0, 0));
        if (glm::length(a) < 1e-9) a = glm::cross(normal, glm::dvec3(0, 1, 0));
        a = glm::normalize(a);
        const glm::dvec3 b = glm::cross(normal, a);
        unsigned char col[3] = {255, 255, 255};
        if (color)
            for (int k = 0; k < 3; ++k)
                col[k] = (unsigned char)color->GetComponent(i, k);
        for (int k = 0; k < S; ++k) {
            const glm::dvec3 w = ringCentre + ringRadius * (cs[std::size_t(k)] * a + sn[std::size_t(k)] * b);
            const vtkIdType id = i * S + k;
            p[3 * id + 0] = float(w.x);
            p[3 * id + 1] = float(w.y);
            p[3 * id + 2] = float(w.z);
            for (int m = 0; m < 3; ++m)
                c[3 * id + m] = col[m];
            lc[i * (S + 1) + k] = id;
        }
        lc[i * (S + 1) + S] = i * S; // close the loop
        lo[i] = i * (S + 1);
        const vtkIdType cid = n * S + i;
        p[3 * cid + 0] = float(centre.x);
        p[3 * cid + 1] = float(centre.y);
        p[3 * cid + 2] = float(centre.z);
        for (int m = 0; m < 3; ++m)
            c[3 * cid + m] = col[m];
        vertConn->SetValue(i, cid);
    }
    lo[n] = n * (S + 1);

    auto lines = vtkSmartPointer<vtkCellArray>::New();
    lines->SetData(lineOffsets, lineConn);
    auto verts = vtkSmartPointer<vtkCellArray>::New();
    verts->SetData(vertOffsets, vertConn);
    out->Initialize();
    out->SetPoints(pts);
    out->SetLines(lines);
    if (n > 0) out->SetVerts(verts);
    out->GetPointData()->AddArray(rgb);
    out->GetPointData()->SetActiveScalars("color");
    return 1;
}

} // namespace lcui
