#pragma once
// Small models shared by the tests.
#include <string>

#include "cases/case_file.hpp"

namespace rfem::test {

/// Path of a file in the source tree.
std::string source_path(const std::string& rel);
/// Two base joints (revolute about z, then revolute about a horizontal axis with an offset) with
/// rigid links, carrying a two-segment link with an offset mass centre, n rfes, gravity on.
/// `stiffness` scales E and G (soft links: every mode slow, for temporal-order tests).
Model spatial_arm(int n, double beta = 0.0, double stiffness = 1.0);
/// Random full state with small flexible coordinates (deterministic seed).
void random_state(const Model& m, unsigned seed, VecX& q, VecX& v, VecX& a);

}  // namespace rfem::test
