#pragma once
// Small models shared by the tests.
#include <string>

#include "../cases/case_file.hpp"

namespace rfem::test {

/// Path of a file in the source tree.
std::string source_path(const std::string& rel);
/// Two base joints (revolute about z, then revolute about a horizontal axis with an offset) with
/// rigid links, carrying a two-segment link with an offset mass centre, n rfes, gravity on.
/// `stiffness` scales E and G (soft links: every mode slow, for temporal-order tests).
Model spatial_arm(int n, double beta = 0.0, double stiffness = 1.0);
/// A tree of every kind of mounting, gravity on: joint 1 (about z, on the ground)
/// carries flexible link A (two segments, offset mass centre, a tip payload); joint 2 sits on A's
/// tip (a turned mount) and carries link B; a wrist joint 3 (about x) with an end-effector body sits
/// on B's tip; a prismatic joint 4 with a slider body rides on B at 0.4 of its length; link C is
/// fixed to A at 0.6 of its length (a branch, no joint). With 3 parts per segment, 4 rfes carry
/// something. `nparts` parts per segment; `beta` sde damping on every link.
Model tree_arm(int nparts = 3, double beta = 0.0);
/// Kane's 10 m cantilever (kane_beam.toml's section) as two flexible links in line, n1 + n2 parts:
/// link 1 (length L1) on the ground, a revolute joint (no body) on its tip about z, link 2 (10 − L1)
/// on that joint; or (`one_link`) the same beam as one link of two segments with those parts.
Model beam_in_two(double L1, int n1, int n2, bool one_link);
/// Random full state with small flexible coordinates (deterministic seed).
void random_state(const Model& m, unsigned seed, VecX& q, VecX& v, VecX& a);

}  // namespace rfem::test
