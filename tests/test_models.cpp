#include "tests/test_models.hpp"

#include <random>

#include "core/rotation.hpp"

namespace rfem::test {

std::string source_path(const std::string& rel) { return std::string(TEST_SOURCE_DIR) + "/" + rel; }

Model spatial_arm(int n, double beta, double stiffness) {
  Material al{"al", 7e10 * stiffness, 2.7e10 * stiffness, 2700};
  Section s1{"s1", 4e-4, 2e-7, 3e-7, 3.5e-7, 0.8, 0.7, Vec3::Zero()};
  Section s2{"s2", 1e-4, 5e-9, 8e-9, 1e-8, 0.6, 0.5, Vec3(0, 0.01, -0.005)};
  FlexibleLink link;
  link.segments = {Segment{1.0, al, s1, 1}, Segment{2.0, al, s2, 1}};
  link.damping_beta = beta;
  const auto parts = distribute_parts(link, n);
  for (size_t i = 0; i < parts.size(); ++i) link.segments[i].parts = parts[i];
  Joint j1, j2;
  j1.H = pseudo_inertia(3.0, Vec3(0.1, 0.05, 0.2), Vec3(0.3, 0.4, 0.2).asDiagonal());
  j2.alpha = 0.7;
  j2.a = 0.5;
  j2.d = 0.1;
  j2.H = pseudo_inertia(2.0, Vec3(0.3, 0.0, -0.1), Vec3(0.05, 0.2, 0.21).asDiagonal());
  const Mat4 mount = homogeneous(rot_rpy(Vec3(0.1, -0.2, 0.3)), Vec3(0.2, 0.1, 0.0));
  return make_model({j1, j2}, mount, discretise(link), 9.81);
}

void random_state(const Model& m, unsigned seed, VecX& q, VecX& v, VecX& a) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const int N = m.dof();
  q.resize(N);
  v.resize(N);
  a.resize(N);
  for (int i = 0; i < N; ++i) {
    const bool base = i >= m.flexible_dofs();
    q[i] = (base ? 1.0 : 0.05) * u(gen);
    v[i] = (base ? 1.0 : 0.2) * u(gen);
    a[i] = u(gen);
  }
}

}  // namespace rfem::test
