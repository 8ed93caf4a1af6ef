#include "views/vtk_adapters.hpp"

#include <vtkCamera.h>

#include <vtkCellArray.h>
#include <vtkDoubleArray.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkUnsignedCharArray.h>

#include <algorithm>

namespace lcui {

vtkSmartPointer<vtkPolyData> meshToPolyData(const lc::Mesh& mesh) {
    auto pts = vtkSmartPointer<vtkPoints>::New();
    pts->SetDataTypeToFloat();
    pts->SetNumberOfPoints(vtkIdType(mesh.vertexCount()));
    for (std::size_t i = 0; i < mesh.vertexCount(); ++i) {
        const glm::dvec4 w = mesh.transform * glm::dvec4(glm::dvec3(mesh.vertex(i)), 1.0);
        pts->SetPoint(vtkIdType(i), w.x, w.y, w.z);
    }
    auto tris = vtkSmartPointer<vtkCellArray>::New();
    tris->AllocateExact(vtkIdType(mesh.triangleCount()), vtkIdType(mesh.indices.size()));
    for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
        const vtkIdType ids[3] = {mesh.indices[3 * t], mesh.indices[3 * t + 1], mesh.indices[3 * t + 2]};
        tris->InsertNextCell(3, ids);
    }
    auto pd = vtkSmartPointer<vtkPolyData>::New();
    pd->SetPoints(pts);
    pd->SetPolys(tris);
    return pd;
}

double lightDisplayRadius(const lc::PointLight& l) {
    return l.validate().empty() ? l.radius() : 0.0;
}

void lightDisplayColor(const lc::PointLight& l, unsigned char rgb[3]) {
    const double m = std::max({l.color.r, l.color.g, l.color.b, 1e-12});
    for (int c = 0; c < 3; ++c)
        rgb[c] = (unsigned char)(std::clamp(l.color[c] / m, 0.0, 1.0) * 255.0 + 0.5);
}

vtkSmartPointer<vtkPolyData> lightsToPolyData(const std::vector<lc::PointLight>& lights) {
    auto pts = vtkSmartPointer<vtkPoints>::New();
    pts->SetDataTypeToDouble();
    pts->SetNumberOfPoints(vtkIdType(lights.size()));
    auto radius = vtkSmartPointer<vtkDoubleArray>::New();
    radius->SetName("radius");
    radius->SetNumberOfValues(vtkIdType(lights.size()));
    auto color = vtkSmartPointer<vtkUnsignedCharArray>::New();
    color->SetName("color");
    color->SetNumberOfComponents(3);
    color->SetNumberOfTuples(vtkIdType(lights.size()));
    for (std::size_t i = 0; i < lights.size(); ++i) {
        const auto& l = lights[i];
        pts->SetPoint(vtkIdType(i), l.position.x, l.position.y, l.position.z);
        radius->SetValue(vtkIdType(i), lightDisplayRadius(l));
        unsigned char rgb[3];
        lightDisplayColor(l, rgb);
        color->SetTypedTuple(vtkIdType(i), rgb);
    }
    auto pd = vtkSmartPointer<vtkPolyData>::New();
    pd->SetPoints(pts);
    pd->GetPointData()->AddArray(radius);
    pd->GetPointData()->AddArray(color);
    pd->GetPointData()->SetActiveScalars("radius");
    return pd;
}

void applyCullingCamera(vtkCamera* vc, const lc::Camera& c) {
    vc->SetPosition(c.position.x, c.position.y, c.position.z);
    vc->SetFocalPoint(c.target.x, c.target.y, c.target.z);
    vc->SetViewUp(c.up.x, c.up.y, c.up.z);
    vc->OrthogonalizeViewUp();
    const bool ortho = lc::isOrthographic(c.projection);
    vc->SetParallelProjection(ortho);
    vc->SetParallelScale(0.5 * c.orthoHeight); // VTK: half the viewport height
    vc->SetViewAngle(c.fovYDeg);               // VTK's view angle is vertical
}

lc::Camera cullingCameraFromVtk(const vtkCamera* cvc, lc::Camera c) {
    auto* vc = const_cast<vtkCamera*>(cvc); // VTK's getters are not const
    double p[3], f[3], u[3];
    vc->GetPosition(p);
    vc->GetFocalPoint(f);
    vc->GetViewUp(u);
    c.position = {p[0], p[1], p[2]};
    c.target = {f[0], f[1], f[2]};
    c.up = {u[0], u[1], u[2]};
    c.fovYDeg = vc->GetViewAngle();
    if (vc->GetParallelProjection()) c.orthoHeight = 2 * vc->GetParallelScale();
    return c;
}

} // namespace lcui
