// Draws several random numbers in an order fixed by the code.
//
// C++ leaves the evaluation order of a call's arguments to the compiler:
// `Eigen::Vector3d(d(rng), d(rng), d(rng))` draws right to left under gcc
// and left to right under clang, so one seed gave two different worlds,
// particle sets and test scenes. Every statement that draws more than once
// spells the order out: separate declarations, a braced list (left to
// right by the standard), or DrawLastFirst. The order chosen is gcc's, the
// compiler every figure so far was made with, so its outputs did not move.
#pragma once

namespace monomap {

// A fixed-size vector (Eigen, or any type with size() and operator[]) of
// independent draws from `dist`, the last element drawn first.
template <typename Vector, typename Distribution, typename Rng>
Vector DrawLastFirst(Distribution& dist, Rng& rng) {
  Vector v;
  for (int i = static_cast<int>(v.size()) - 1; i >= 0; --i) v[i] = dist(rng);
  return v;
}

}  // namespace monomap
