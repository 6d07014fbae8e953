#pragma once
// Picking on the CPU: which surface point lies under a pixel, for placing heat sources and probes from
// the browser. Uses the same fields and iso-level as the ray caster, so a pick lands where the user sees
// the surface (to within the GPU's single-precision march).
#include <Eigen/Core>

#include "render/camera.h"
#include "render/density_field.h"

namespace thaw {

// Marches camera.ray(px, py) (pixel coordinates as OrbitCamera::ray: the centre of pixel (x, y) is at
// (x, y), y counted down from the top) through the union of the phases' fields and refines the first
// iso crossing by bisection. `hit` is that point [m]; `normal` the unit outward surface normal there
// (minus the field gradient). Returns false, leaving both untouched, when the ray meets no surface.
bool pick(const DensityFields& fields, const OrbitCamera& camera, double px, double py, Eigen::Vector3d& hit,
          Eigen::Vector3d& normal);

}  // namespace thaw
