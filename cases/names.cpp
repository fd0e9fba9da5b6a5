#include "names.hpp"

#include <array>
#include <utility>

namespace rfem {

namespace {

template <class E, size_t N>
std::string name_of(const std::array<std::pair<E, const char*>, N>& table, E e) {
  for (const auto& [k, n] : table)
    if (k == e) return n;
  return "?";
}
template <class E, size_t N>
bool parse_name(const std::array<std::pair<E, const char*>, N>& table, const std::string& name, E& e) {
  for (const auto& [k, n] : table)
    if (name == n) {
      e = k;
      return true;
    }
  return false;
}

constexpr std::array<std::pair<InputKind, const char*>, 8> kInputs{{{InputKind::Deployment, "deployment"},
                                                                      {InputKind::Spinup, "spinup"},
                                                                      {InputKind::ConstantRate, "constant_rate"},
                                                                      {InputKind::Table, "table"},
                                                                      {InputKind::Torque, "torque"},
                                                                      {InputKind::TorqueTable, "torque_table"},
                                                                      {InputKind::TorqueFromRun, "torque_from_run"},
                                                                      {InputKind::Pd, "pd"}}};
constexpr std::array<std::pair<Procedure, const char*>, 2> kProcedures{{{Procedure::Single, "single"}, {Procedure::Paper, "paper"}}};
constexpr std::array<std::pair<RunName, const char*>, 4> kRuns{
    {{RunName::Run, "run"}, {RunName::Rigid, "rigid"}, {RunName::Kinematic, "kinematic"}, {RunName::Force, "force"}}};
constexpr std::array<std::pair<Feedforward, const char*>, 2> kFeedforward{{{Feedforward::None, "none"}, {Feedforward::Rigid, "rigid"}}};

}  // namespace

std::string to_string(InputKind k) { return name_of(kInputs, k); }
bool parse(const std::string& name, InputKind& k) { return parse_name(kInputs, name, k); }
std::string input_kind_names() {
  std::string s;
  for (const auto& [k, n] : kInputs) s += (s.empty() ? "" : ", ") + std::string(n);
  return s;
}
bool is_motion(InputKind k) {
  return k == InputKind::Deployment || k == InputKind::Spinup || k == InputKind::ConstantRate || k == InputKind::Table;
}

std::string to_string(Procedure p) { return name_of(kProcedures, p); }
bool parse(const std::string& name, Procedure& p) { return parse_name(kProcedures, name, p); }

std::string to_string(RunName r) { return name_of(kRuns, r); }
bool parse(const std::string& name, RunName& r) { return parse_name(kRuns, name, r); }
std::vector<RunName> runs_of(Procedure p) {
  if (p == Procedure::Paper) return {RunName::Rigid, RunName::Kinematic, RunName::Force};
  return {RunName::Run};
}

std::string to_string(Feedforward f) { return name_of(kFeedforward, f); }
bool parse(const std::string& name, Feedforward& f) { return parse_name(kFeedforward, name, f); }

}  // namespace rfem
