// Case files: the shipped cases load; --set overrides reach the model; bad input gives one-line
// errors naming file, line and key.
#include <gtest/gtest.h>

#include <fstream>

#include "rfem/cases/case_file.hpp"
#include "tests/test_models.hpp"

using namespace rfem;

namespace {
std::string write_case(const std::string& name, const std::string& text) {
  const std::string path = testing::TempDir() + name;
  std::ofstream(path) << text;
  return path;
}

const char* kGood = R"([materials.al]
E = 7e10
G = 2.7e10
rho = 2700

[sections.s]
A = 4e-4
Iy = 2e-7
Iz = 2e-7
J = 4e-7

[link]
n = 4

[[link.segments]]
length = 2.0
material = "al"
section = "s"
)";

std::string error_of(const std::string& text, std::vector<std::string> overrides = {}) {
  const std::string path = write_case("bad.toml", text);
  try {
    read_case(path, overrides);
    build_model(read_case(path, overrides));
  } catch (const CaseError& e) {
    return e.what();
  }
  return "no error";
}

std::string replace(std::string s, const std::string& from, const std::string& to) {
  s.replace(s.find(from), from.size(), to);
  return s;
}
}  // namespace

TEST(CaseFile, ShippedCasesLoad) {
  for (const char* f : {"cases/kane_beam.toml", "cases/paper_link3.toml", "cases/paper_manipulator.toml"}) {
    const Case c = read_case(test::source_path(f));
    const Model m = build_model(c);
    EXPECT_GT(m.n(), 0) << f;
  }
  const Model pm = build_model(read_case(test::source_path("cases/paper_manipulator.toml")));
  EXPECT_EQ(pm.m(), 3);
  EXPECT_EQ(pm.n(), 6);
  // n = 6 over 2.667 m + 5.333 m: 2 + 4 parts, total mass ρ(A1 L1 + A2 L2).
  double mass = pm.links[0].d.rfe0.mass;
  for (const auto& r : pm.links[0].d.rfes) mass += r.mass;
  EXPECT_NEAR(mass, 2766.67 * (3.84e-4 * 2.667 + 7.3e-5 * 5.333), 1e-12);
}

TEST(CaseFile, OverridesApply) {
  const std::string path = write_case("good.toml", kGood);
  const Case c = read_case(path, {"link.n=10", "sections.s.Iy=3e-7", "link.segments.0.length=4"});
  EXPECT_EQ(build_model(c).n(), 10);
  EXPECT_DOUBLE_EQ(c.links[0].link.segments[0].section.Iy, 3e-7);
  EXPECT_DOUBLE_EQ(c.links[0].link.segments[0].length, 4.0);
}

TEST(CaseFile, BadInputNamesFileLineAndKey) {
  EXPECT_NE(error_of(replace(kGood, "E = 7e10", "E = -7e10")).find("bad.toml:2: materials.al.E: must be positive"), std::string::npos);
  EXPECT_NE(error_of(replace(kGood, "length = 2.0", "length = nan")).find("link.segments.0.length: must be finite"), std::string::npos);
  EXPECT_NE(error_of(replace(kGood, "n = 4", "n = 4\nspeed = 3")).find(":14: link.speed: unknown key"), std::string::npos);
  EXPECT_NE(error_of(replace(kGood, "A = 4e-4\n", "")).find("sections.s.A: missing"), std::string::npos);
  EXPECT_NE(error_of(replace(kGood, "Iy = 2e-7", "Iy = \"big\"")).find("sections.s.Iy: must be a number, not a string"), std::string::npos);
  EXPECT_NE(error_of(replace(kGood, "rho = 2700", "rho = 2700 =")).find("bad.toml:4: syntax error"), std::string::npos);
  EXPECT_NE(error_of(replace(kGood, "material = \"al\"", "material = \"steel\"")).find("no material named 'steel'"), std::string::npos);
  EXPECT_NE(error_of(replace(kGood, "n = 4", "n = 0")).find("link.n: must be at least 1"), std::string::npos);
  EXPECT_NE(error_of(kGood, {"link.nope.x=1"}).find("link.nope: unknown key"), std::string::npos);
  EXPECT_NE(error_of(kGood, {"link.n"}).find("expected key.path=value"), std::string::npos);
}
