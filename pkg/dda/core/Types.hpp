// Basic types shared by every layer of the core (pkg/dda/core: the bottom
// layer, which includes nothing of yade-dda). Units are those of the values
// they hold: SI metres for positions in yade-dda.
#pragma once

#include <Eigen/Core>

namespace dda {

using Vector3 = Eigen::Vector3d;
using Matrix3 = Eigen::Matrix3d;

}  // namespace dda
