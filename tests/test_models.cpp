#include "tests/test_models.hpp"

#include <random>

#include "../core/rotation.hpp"

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

Model tree_arm(int nparts, double beta) {
  Material al{"al", 7e10, 2.7e10, 2700};
  Section s1{"s1", 4e-4, 2e-7, 3e-7, 3.5e-7, 0.8, 0.7, Vec3::Zero()};
  Section s2{"s2", 1e-4, 5e-9, 8e-9, 1e-8, 0.6, 0.5, Vec3(0, 0.01, -0.005)};
  auto link = [&](std::vector<Segment> segs, std::string name, Mounting on) {
    FlexibleLink f;
    f.segments = std::move(segs);
    f.damping_beta = beta;
    MountedLink L;
    L.name = std::move(name);
    L.d = discretise(f);
    L.on = on;
    return L;
  };
  auto on = [](Mounting::Kind k, int index, double at, const Mat4& X) {
    Mounting m;
    m.kind = k;
    m.index = index;
    m.at = at;
    m.X = X;
    return m;
  };
  FlexibleLink fa;
  fa.segments = {Segment{1.0, al, s1, nparts}, Segment{1.5, al, s2, nparts}};
  fa.payloads = {Payload{2.5, pseudo_inertia(0.4, Vec3(0.02, 0, 0.01), Vec3(1e-3, 2e-3, 2e-3).asDiagonal())}};
  fa.damping_beta = beta;
  MountedLink A;
  A.name = "A";
  A.d = discretise(fa);
  A.on = on(Mounting::Kind::Joint, 0, -1, homogeneous(rot_rpy(Vec3(0.1, -0.2, 0.3)), Vec3(0.2, 0.1, 0.0)));
  MountedLink B = link({Segment{1.2, al, s1, nparts}}, "B", on(Mounting::Kind::Joint, 1, -1, homogeneous(rot_rpy(Vec3(0.0, 0.1, 0.0)), Vec3(0.05, 0, 0))));
  MountedLink C = link({Segment{0.5, al, s2, nparts}}, "C", on(Mounting::Kind::Link, 0, 0.6 * 2.5, homogeneous(rot_rpy(Vec3(0.3, 0.0, 1.2)), Vec3::Zero())));
  Joint j1, j2, j3, j4;
  j1.name = "shoulder";
  j1.H = pseudo_inertia(3.0, Vec3(0.1, 0.05, 0.2), Vec3(0.3, 0.4, 0.2).asDiagonal());
  j1.on = on(Mounting::Kind::Ground, -1, -1, Mat4::Identity());
  j2.name = "elbow";
  j2.alpha = 0.4;
  j2.H = pseudo_inertia(0.8, Vec3(0.02, 0.0, -0.01), Vec3(0.01, 0.02, 0.015).asDiagonal());
  j2.on = on(Mounting::Kind::Link, 0, 2.5, homogeneous(rot_rpy(Vec3(0.2, 0.0, -0.3)), Vec3(0.03, 0, 0)));
  j3.name = "wrist";
  j3.axis = Vec3::UnitX();
  j3.H = pseudo_inertia(0.5, Vec3(0.05, 0.01, 0.0), Vec3(2e-3, 3e-3, 1e-3).asDiagonal());
  j3.on = on(Mounting::Kind::Link, 1, 1.2, Mat4::Identity());
  j4.name = "slider";
  j4.type = JointType::Prismatic;
  j4.axis = Vec3(0.0, 0.6, 0.8);
  j4.H = pseudo_inertia(0.3, Vec3(0.0, 0.02, 0.0), Vec3(1e-4, 1e-4, 1e-4).asDiagonal());
  j4.on = on(Mounting::Kind::Link, 1, 0.4 * 1.2, homogeneous(Mat3::Identity(), Vec3(0, 0.01, 0)));
  return make_model({j1, j2, j3, j4}, {A, B, C}, 9.81);
}

Model beam_in_two(double L1, int n1, int n2, bool one_link) {
  const Case c = read_case(source_path("cases/kane_beam.toml"));
  Segment s = c.links[0].link.segments[0];
  Segment a = s, b = s;
  a.length = L1;
  a.parts = n1;
  b.length = s.length - L1;
  b.parts = n2;
  if (one_link) {
    FlexibleLink f;
    f.segments = {a, b};
    return make_model({}, Mat4::Identity(), discretise(f), 0.0);
  }
  FlexibleLink f1, f2;
  f1.segments = {a};
  f2.segments = {b};
  MountedLink l1, l2;
  l1.name = "inner";
  l1.d = discretise(f1);
  l1.on.kind = Mounting::Kind::Ground;
  l2.name = "outer";
  l2.d = discretise(f2);
  l2.on.kind = Mounting::Kind::Joint;
  l2.on.index = 0;
  Joint j;  // no body: locked, the two links are one beam
  j.name = "middle";
  j.on.kind = Mounting::Kind::Link;
  j.on.index = 0;
  return make_model({j}, {l1, l2}, 0.0);
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
