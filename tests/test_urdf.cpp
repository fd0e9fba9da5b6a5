// URDF bases (cases/read_urdf.cpp): the arm of cases/urdf/three_link_arm.urdf with its flexible
// tube (cases/urdf_arm.toml) against its twin written in TOML joints
// (tests/urdf/three_link_arm_twin.toml, whose header derives the welded forearm's inertia by the
// parallel-axis rule): the same torques, deflections, statics and frequencies to round-off. And the
// gravity torques the held arm needs, from its mass distribution alone.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "../studies/modes_study.hpp"
#include "../studies/runs.hpp"
#include "../studies/show.hpp"
#include "../studies/static_study.hpp"
#include "tests/test_models.hpp"

using namespace rfem;

namespace {
const std::vector<std::string> kShort = {"simulation.t_end=1.0"};
Case urdf_arm() { return read_case(test::source_path("cases/urdf_arm.toml"), kShort); }
Case twin() { return read_case(test::source_path("tests/urdf/three_link_arm_twin.toml"), kShort); }

// Round-off: both models compose the same transforms in a different order (the URDF's quaternion
// rotations, the TOML's rpy; the tool's inertia welded by a transform against its decimal form), so
// results agree to a few ulps of their scale, amplified by the integrator's Newton tolerance no
// more than the same steps allow: 1e-10 of each series' scale.
void expect_close(const Table& a, const Table& b, const std::string& what) {
  ASSERT_EQ(a.rows, b.rows) << what;
  ASSERT_EQ(a.cols, b.cols) << what;
  double scale = 0.0, diff = 0.0;
  for (size_t i = 0; i < a.data.size(); ++i) {
    scale = std::max(scale, std::abs(a.data[i]));
    diff = std::max(diff, std::abs(a.data[i] - b.data[i]));
  }
  EXPECT_LE(diff, 1e-10 * scale) << what << ": scale " << scale;
  EXPECT_GT(scale, 0.0) << what;
}
}  // namespace

TEST(Urdf, BuildsTheJointsFramesAndBodiesOfItsTwin) {
  const Case u = urdf_arm(), t = twin();
  ASSERT_EQ(u.joints.size(), 3u);
  EXPECT_EQ(u.joints[0].name, "waist");
  EXPECT_EQ(u.joints[2].name, "elbow");
  EXPECT_NE(u.urdf.find("three_link_arm.urdf"), std::string::npos);
  for (size_t j = 0; j < 3; ++j) {
    EXPECT_LE((u.joints[j].H - t.joints[j].H).cwiseAbs().maxCoeff(), 1e-15) << j;
    EXPECT_LE((u.joints[j].on.X - t.joints[j].on.X).cwiseAbs().maxCoeff(), 1e-15) << j;
    EXPECT_EQ(u.joints[j].axis, t.joints[j].axis) << j;
    EXPECT_EQ(u.joints[j].drive.damping, t.joints[j].drive.damping) << j;
    EXPECT_EQ(u.joints[j].drive.friction, t.joints[j].drive.friction) << j;
  }
  // The tube on the URDF's tool0 sits on the elbow's body 0.2 m out, as in the twin.
  EXPECT_EQ(u.links[0].on.kind, Mounting::Kind::Joint);
  EXPECT_EQ(u.links[0].on.index, 2);
  EXPECT_LE((u.links[0].on.X - t.links[0].on.X).cwiseAbs().maxCoeff(), 1e-15);
  // Every URDF link is a frame; the root is the ground.
  ASSERT_EQ(u.frames.size(), 5u);  // base_link, turret, upper_arm, forearm, tool0
  const auto root = std::find_if(u.frames.begin(), u.frames.end(), [](const BodyFrame& f) { return f.name == "base_link"; });
  ASSERT_NE(root, u.frames.end());
  EXPECT_EQ(root->joint, -1);
}

TEST(Urdf, RunsLikeItsTwin) {
  RunRequest rq;
  rq.threads = 1;
  const std::vector<RunResult> a = run_case(urdf_arm(), rq), b = run_case(twin(), rq);
  ASSERT_TRUE(a[0].completed()) << a[0].status;
  ASSERT_TRUE(b[0].completed()) << b[0].status;
  for (const std::string name : {"joint_tau", "tip_deflection", "links/tube/tip"})
    expect_close(a[0].series->table(name), b[0].series->table(name), name);
}

TEST(Urdf, StaticsAndFrequenciesLikeItsTwin) {
  const StaticStudy a = static_study(urdf_arm()), b = static_study(twin());
  EXPECT_LE((a.tips[0].motion - b.tips[0].motion).cwiseAbs().maxCoeff(), 1e-12 * a.tips[0].motion.cwiseAbs().maxCoeff());
  ModesRequest rq;
  rq.count = 6;
  const ModesStudy ma = modes_study(urdf_arm(), rq), mb = modes_study(twin(), rq);
  ASSERT_EQ(ma.modes.omega.size(), 6);
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(ma.modes.omega[k], mb.modes.omega[k], 1e-10 * mb.modes.omega[k]) << k;
}

TEST(Urdf, HeldArmNeedsTheTorquesOfItsWeight) {
  // At t = 0 the arm is at rest (the deployment law starts with zero rate and acceleration) in
  // static equilibrium: the shoulder and elbow hold the moments of every mass beyond them about
  // their horizontal axes, g Σ m x, and the waist holds nothing. The tube's sag (1.6 mm) shortens
  // its lever by u²/L ~ 1e-6 relative: the bound.
  RunRequest rq;
  rq.threads = 1;
  const std::vector<RunResult> r = run_case(urdf_arm(), rq);
  const Table tau = r[0].series->table("joint_tau");
  const double g = 9.81, tube = 2700.0 * (0.03 * 0.03 - 0.027 * 0.027) * 1.2;
  const double shoulder = g * (3.0 * 0.25 + 2.0 * 0.625 + tube * 1.3 + 0.2 * 1.9);
  const double elbow = g * (2.0 * 0.125 + tube * 0.8 + 0.2 * 1.4);
  EXPECT_NEAR(tau.at(0, 0), 0.0, 1e-9);
  // Positive rotation about y lowers the arm: holding it against gravity takes a negative torque.
  EXPECT_NEAR(-tau.at(0, 1), shoulder, 1e-5 * shoulder);
  EXPECT_NEAR(-tau.at(0, 2), elbow, 1e-5 * elbow);
}

TEST(Urdf, RunsWarnWhereTheJointsLeaveTheirRatedLimits) {
  // The shoulder holds ~30 N m (the test above) and turns at up to π/6 · 2/2 ≈ 0.52 rad/s: rated
  // 300 N m and 2 rad/s in the URDF it draws no warning; rated 5 N m and 0.3 rad/s it draws two.
  std::ifstream in(test::source_path("cases/urdf/three_link_arm.urdf"));
  std::stringstream text;
  text << in.rdbuf();
  std::string urdf = text.str();
  const std::string rated = R"(effort="300" velocity="2.0")";
  ASSERT_NE(urdf.find(rated), std::string::npos);
  urdf.replace(urdf.find(rated), rated.size(), R"(effort="5" velocity="0.3")");
  const std::string path = (std::filesystem::temp_directory_path() / "rfem_test_weak_arm.urdf").string();
  std::ofstream(path) << urdf;
  RunRequest rq;
  rq.threads = 1;
  auto joint_warnings = [](const RunResult& r) {
    std::vector<std::string> w;
    for (const std::string& x : r.warnings)
      if (x.find("joint '") != std::string::npos) w.push_back(x);
    return w;
  };
  EXPECT_TRUE(joint_warnings(run_case(urdf_arm(), rq)[0]).empty());
  const Case weak = with_overrides(urdf_arm(), {"base.urdf=\"" + path + "\""});
  const std::vector<std::string> w = joint_warnings(run_case(weak, rq)[0]);
  ASSERT_EQ(w.size(), 2u);
  EXPECT_NE(w[0].find("joint 'shoulder': its rate exceeded its rated 0.3 rad/s by up to 0.2"), std::string::npos) << w[0];
  EXPECT_NE(w[1].find("joint 'shoulder': its torque exceeded its rated 5 N m by up to 2"), std::string::npos) << w[1];
  std::filesystem::remove(path);
}

namespace {
// The shipped arm's URDF with `from` replaced by `to`, in a temporary file; the error of reading
// the arm's case on it ("no error" if none).
std::string error_with(const std::string& from, const std::string& to) {
  std::ifstream in(test::source_path("cases/urdf/three_link_arm.urdf"));
  std::stringstream text;
  text << in.rdbuf();
  std::string urdf = text.str();
  if (urdf.find(from) == std::string::npos) return "'" + from + "' not in the URDF";
  urdf.replace(urdf.find(from), from.size(), to);
  const std::string path = (std::filesystem::temp_directory_path() / "rfem_test_changed_arm.urdf").string();
  std::ofstream(path) << urdf;
  std::string what = "no error";
  try {
    read_case(test::source_path("cases/urdf_arm.toml"), {"base.urdf=\"" + path + "\""});
  } catch (const CaseError& e) {
    what = e.what();
  }
  std::filesystem::remove(path);
  return what;
}
}  // namespace

TEST(Urdf, EveryNumberIsANumber) {
  // urdfdom reads "three" as 0 kg, "3.0 4.0" as 3 kg and takes NaN: each is refused, naming the
  // file, line, link or joint and attribute.
  const std::string mass = R"(<mass value="3.0"/>)";
  std::string e = error_with(mass, R"(<mass value="three"/>)");
  EXPECT_NE(e.find("rfem_test_changed_arm.urdf:40: link 'upper_arm': <mass value=\"three\">: must be a finite number"), std::string::npos) << e;
  e = error_with(mass, R"(<mass value="3.0 4.0"/>)");
  EXPECT_NE(e.find("link 'upper_arm': <mass value=\"3.0 4.0\">: must be a finite number"), std::string::npos) << e;
  e = error_with(R"(ixx="0.03")", R"(ixx="nan")");
  EXPECT_NE(e.find("link 'turret': <inertia ixx=\"nan\">: must be a finite number"), std::string::npos) << e;
  e = error_with(R"(<axis xyz="0 0 1"/>)", R"(<axis xyz="0 0 1 0"/>)");
  EXPECT_NE(e.find("joint 'waist': <axis xyz=\"0 0 1 0\">: must be 3 finite numbers"), std::string::npos) << e;
  e = error_with(R"(lower="-2.0")", R"(lower="-2,0")");
  EXPECT_NE(e.find("joint 'shoulder': <limit lower=\"-2,0\">: must be a finite number"), std::string::npos) << e;
  e = error_with(R"(damping="0.5")", R"(damping="inf")");
  EXPECT_NE(e.find("joint 'waist': <dynamics damping=\"inf\">: must be a finite number"), std::string::npos) << e;
  EXPECT_EQ(error_with(R"(<origin xyz="0 0 0.3" rpy="0 0 0"/>)", R"(<origin xyz=" +0 0  3e-1 " rpy="0 0 0"/>)"), "no error");
}

TEST(Urdf, ALinkWithTwoParentJointsIsRefused) {
  // urdfdom kept one of them and dropped the other without a word.
  const std::string e = error_with("</robot>", R"(<joint name="extra" type="fixed"><parent link="base_link"/><child link="forearm"/></joint></robot>)");
  EXPECT_NE(e.find("link 'forearm' has two parent joints, 'elbow' and 'extra'"), std::string::npos) << e;
}

TEST(Urdf, AJointGivenNoInputIsSaidToBeFree) {
  // Once at reading, for every such joint together, and on the joint's line of `rfem show`.
  EXPECT_TRUE(urdf_arm().warnings.empty());
  std::ifstream in(test::source_path("cases/urdf_arm.toml"));
  std::stringstream text;
  text << in.rdbuf();
  std::string toml = text.str();
  const size_t from = toml.find("[base.joints.shoulder]"), to = toml.find("[materials.");
  ASSERT_LT(from, to);
  toml.erase(from, to - from);  // the shoulder's and the elbow's tables
  const Case c = parse_case(toml, "arm.toml", kShort, test::source_path("cases/"));
  ASSERT_EQ(c.warnings.size(), 1u);
  EXPECT_NE(c.warnings[0].find("base.joints: URDF joints 'shoulder', 'elbow' have no input: free, under zero torque"),
            std::string::npos) << c.warnings[0];
  EXPECT_FALSE(c.inputs[0].none_given);
  EXPECT_TRUE(c.inputs[1].none_given && c.inputs[2].none_given);
  const std::string tree = format_summary(show_model(c));
  EXPECT_NE(tree.find("joint elbow — on shoulder: revolute about y; input none given: free, under zero torque"), std::string::npos) << tree;
}
