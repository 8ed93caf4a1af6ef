#pragma once
// Adapters from the culling library's plain structs to VTK data, at the edge
// of the UI (the library itself never sees VTK).

#include "culling/scene/scene.hpp"

#include <vtkSmartPointer.h>

class vtkCamera;
class vtkPolyData;

namespace lcui {

// World-space triangles of a mesh (its transform applied), float points.
vtkSmartPointer<vtkPolyData> meshToPolyData(const lc::Mesh& mesh);

// One point per light at its world position, with point data
//   "radius" (double): the bounding-sphere radius, the glyph scale,
//   "color"  (uchar RGB): the light's colour normalised to its brightest
//            channel (linear RGB > 1 still shows its hue).
// A light that fails validation gets radius 0 (it is reported by the run).
vtkSmartPointer<vtkPolyData> lightsToPolyData(const std::vector<lc::PointLight>& lights);

// Light colour for display: normalised to the brightest channel, 0..255.
void lightDisplayColor(const lc::PointLight& l, unsigned char rgb[3]);

// Radius of a light for display; 0 when the light does not validate.
double lightDisplayRadius(const lc::PointLight& l);

// The culling camera as a VTK camera: position, focal point = target, view
// up (orthogonalised), parallel projection for the orthographic kinds with
// parallel scale = half the ortho height, else the vertical view angle =
// fovY. Clipping is left to the caller (VTK's depth range is not the
// culling's).
void applyCullingCamera(vtkCamera* vc, const lc::Camera& c);
// The inverse for the fields VTK holds: `base` with position, target, up and
// fovY (or, for a parallel VTK camera, orthoHeight) taken from `vc`.
lc::Camera cullingCameraFromVtk(const vtkCamera* vc, lc::Camera base);

} // namespace lcui
