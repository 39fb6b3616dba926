// Degrees <-> radians. Multiplying by the constant (rather than
// `deg * M_PI / 180`) is the project's convention: the two round
// differently in the last bit, and results are compared bit for bit.
// The angle between two rotations is AngleBetween (geometry/rigid3.h).
#pragma once

#include <cmath>

namespace monomap {

// (No named constants: files with a local kDegToRad would clash.)
constexpr double DegToRad(double degrees) { return degrees * (M_PI / 180.0); }
constexpr double RadToDeg(double radians) { return radians * (180.0 / M_PI); }

// The same conversions as `deg * M_PI / 180.0` and `rad * 180.0 / M_PI`
// (multiply, then divide), for the outputs that were made that way and are
// compared bit for bit (simulated datasets, reports): switching them to the
// functions above would move their last bits.
constexpr double DegToRadMulDiv(double degrees) {
  return degrees * M_PI / 180.0;
}
constexpr double RadToDegMulDiv(double radians) {
  return radians * 180.0 / M_PI;
}

}  // namespace monomap
