#pragma once
// The cheap light representation of the inspector view: each light's sphere
// as its silhouette, the circle where the sphere's outline lies as seen from
// the camera, drawn as one closed polyline coloured by the light's colour.
//
// Why: the software rasteriser (llvmpipe) pays for every covered pixel, and
// 1,024 translucent filled spheres cover the view many times over; a ring
// costs its perimeter instead of its area. The outline is exact for a sphere
// (perspective: the circle of tangency, pulled towards the eye and shrunk),
// so the ring shows the light's extent as the filled sphere did.
//
// Input: the lights as points with a "radius" and a "color" point array
// (lightsToPolyData). Output: kSegments points per light, light i's at
// [i * kSegments, (i + 1) * kSegments), one closed polyline each, then every
// light's centre (one poly-vertex cell) so a dense cloud still shows where
// each light sits; "color" per point. Re-executes when the camera moves (its
// MTime is part of this filter's). A light whose radius is 0 (invalid) gets a
// ring collapsed onto its centre.

#include <vtkPolyDataAlgorithm.h>
#include <vtkSmartPointer.h>

class vtkCamera;

namespace lcui {

class LightSilhouettes : public vtkPolyDataAlgorithm {
  public:
    static LightSilhouettes* New();
    vtkTypeMacro(LightSilhouettes, vtkPolyDataAlgorithm);

    static constexpr int kSegments = 24;

    void SetCamera(vtkCamera* camera);
    vtkCamera* GetCamera() const { return camera_; }
    vtkMTimeType GetMTime() override;

  protected:
    LightSilhouettes();
    ~LightSilhouettes() override;
    int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  private:
    LightSilhouettes(const LightSilhouettes&) = delete;
    void operator=(const LightSilhouettes&) = delete;
    vtkSmartPointer<vtkCamera> camera_;
};

} // namespace lcui
