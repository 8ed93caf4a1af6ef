#pragma once
// The spot lights' cones in the inspector view: one wireframe actor for all
// spot lights (apex-to-rim lines, the rim circle and two arcs of the
// spherical cap, world space, in each light's display colour). The inspector
// view owns one and calls update() when lights change.

#include "culling/scene/scene.hpp"

#include <vtkSmartPointer.h>

#include <vector>

class vtkActor;
class vtkPolyData;
class vtkRenderer;

namespace lcui {

// The cones as line cells. `segments` points per rim circle (>= 3). Point
// lights and invalid lights contribute nothing. Point data "color" (RGB bytes).
vtkSmartPointer<vtkPolyData> spotConesToPolyData(const std::vector<lc::PointLight>& lights, int segments = 32);

class SpotConesActor {
public:
    explicit SpotConesActor(vtkRenderer* renderer);
    void update(const std::vector<lc::PointLight>& lights);
    vtkActor* actor() const;
    vtkPolyData* data() const;

private:
    vtkSmartPointer<vtkPolyData> data_;
    vtkSmartPointer<vtkActor> actor_;
};

} // namespace lcui
