#include "views/spot_actor.hpp"

#include "views/vtk_adapters.hpp"

#include <vtkActor.h>
#include <vtkCellArray.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderer.h>
#include <vtkUnsignedCharArray.h>

#include <glm/gtc/constants.hpp>

#include <cmath>

namespace lcui {

vtkSmartPointer<vtkPolyData> spotConesToPolyData(const std::vector<lc::PointLight>& lights, int segments) {
    segments = std::max(segments, 3);
    auto pts = vtkSmartPointer<vtkPoints>::New();
    auto lines = vtkSmartPointer<vtkCellArray>::New();
    auto color = vtkSmartPointer<vtkUnsignedCharArray>::New();
    color->SetName("color");
    color->SetNumberOfComponents(3);
    for (const auto& l : lights) {
        if (!l.isSpot() || !l.validate().empty()) continue;
        unsigned char rgb[3];
        lightDisplayColor(l, rgb);
        const glm::dvec3 axis = glm::normalize(l.direction);
        const glm::dvec3 e1 = glm::normalize(
            glm::cross(axis, std::abs(axis.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0)));
        const glm::dvec3 e2 = glm::cross(axis, e1);
        const double range = l.radius();
        const double a = glm::radians(l.outerAngleDeg);
        auto add = [&](const glm::dvec3& p) {
            color->InsertNextTypedTuple(rgb);
            return pts->InsertNextPoint(p.x, p.y, p.z);
        };
        // Point of the spherical cap at polar angle th, azimuth ph.
        auto cap = [&](double th, double ph) {
            return l.position + range * (std::cos(th) * axis + std::sin(th) * (std::cos(ph) * e1 + std::sin(ph) * e2));
        };
        const vtkIdType apex = add(l.position);
        std::vector<vtkIdType> rim(std::size_t(segments) + 1);
        for (int i = 0; i < segments; ++i) rim[std::size_t(i)] = add(cap(a, 2 * glm::pi<double>() * i / segments));
        rim[std::size_t(segments)] = rim[0];
        lines->InsertNextCell(vtkIdType(rim.size()), rim.data()); // the rim circle
        for (int i = 0; i < 8; ++i) {                              // 8 generators
            const vtkIdType ids[2] = {apex, rim[std::size_t(i * segments / 8)]};
            lines->InsertNextCell(2, ids);
        }
        // Two arcs over the cap through its tip, in the e1 and e2 planes.
        for (double ph : {0.0, 0.5 * glm::pi<double>()}) {
            const int n = 12;
            std::vector<vtkIdType> arc;
            for (int k = -n; k <= n; ++k) arc.push_back(add(cap(a * std::abs(k) / n, k < 0 ? ph + glm::pi<double>() : ph)));
            lines->InsertNextCell(vtkIdType(arc.size()), arc.data());
        }
    }
    auto pd = vtkSmartPointer<vtkPolyData>::New();
    pd->SetPoints(pts);
    pd->SetLines(lines);
    pd->GetPointData()->SetScalars(color);
    return pd;
}

SpotConesActor::SpotConesActor(vtkRenderer* renderer) {
    data_ = spotConesToPolyData({});
    auto mapper = vtkSmartPointer<vtkPolyDataMapper>::New();
    mapper->SetInputData(data_);
    mapper->SetScalarModeToUsePointData();
    mapper->SetColorModeToDirectScalars();
    actor_ = vtkSmartPointer<vtkActor>::New();
    actor_->SetMapper(mapper);
    actor_->GetProperty()->SetLineWidth(2.0);
    actor_->PickableOff();
    if (renderer) renderer->AddActor(actor_);
}

vtkActor* SpotConesActor::actor() const { return actor_; }
vtkPolyData* SpotConesActor::data() const { return data_; }

void SpotConesActor::update(const std::vector<lc::PointLight>& lights) {
    data_->ShallowCopy(spotConesToPolyData(lights));
    data_->Modified();
}

} // namespace lcui
