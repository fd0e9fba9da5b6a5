// `rfem modes`: natural frequencies with their exact references where they apply.
#include <fmt/core.h>
#include <fmt/ranges.h>

#include <optional>

#include "commands.hpp"
#include "../results/errors.hpp"
#include "../studies/run_file.hpp"

namespace rfem::app {

int run_modes(const Common& c, const ModesOptions& o) {
  const Case cs = read_checked_case(c);
  ModesRequest rq;
  rq.n = c.n;
  rq.count = o.count;
  rq.rate = o.rate;
  rq.free = o.free;
  // A target: n from a refinement of the frequencies (studies/accuracy.hpp), then the modes there.
  const AccuracySpec target = accuracy_target(cs, c);
  std::optional<AccuracyResult> acc;
  if (target.given()) {
    RefineRequest base;
    base.rate = o.rate;
    base.free = o.free;
    base.threads = c.threads;
    base.warn = print_warning;
    base.on_n = ladder_lines(target, c.json || c.quiet);
    acc = meet_accuracy(cs, target, reported_by_modes(o.count), base);
    rq.n = acc->n;
  }
  ModesStudy s;
  try {
    s = modes_into_file(cs, rq, o.output, c.command_line, max_threads(c));
  } catch (const ResultsError& e) {  // (a path that cannot be written: the program's usage error)
    throw CaseError(e.what());
  }
  const Model& model = *s.model;
  const ModesResult& r = s.modes;
  const int nf = static_cast<int>(s.free.size());
  if (s.requested > s.count && !c.json)
    fmt::print(stderr, "rfem: note: --count {} capped at 6n{} = {} (every mode of n = {} rfes{})\n", s.requested,
               nf ? fmt::format(" + {}", nf) : "", s.count, model.n(), nf ? fmt::format(" and {} free joints", nf) : "");
  const VecX& vb = s.rates;
  if (!c.json)
    fmt::print("modes of {} with n = {} rfes ({} solver){}{}\n{:>4} {:>14} {:>14} {:>12}{}\n",
               cs.name.empty() ? cs.path : cs.name, model.n(), r.dense ? "dense" : "shift-invert Lanczos",
               nf ? fmt::format(", free joints {}", fmt::join(s.free_names, " ")) : "",
               vb.size() && vb.norm() > 0 ? fmt::format(", joint rates {}", fmt::join(vb.data(), vb.data() + vb.size(), " ")) : "",
               "mode", "f [Hz]", "omega [rad/s]", "kind",
               s.has_reference ? fmt::format(" {:>16} {:>10} {:>16}", "reference [Hz]", "error", "Euler-Bern. [Hz]") : "");
  nlohmann::json modes = nlohmann::json::array();
  for (int i = 0; i < s.count; ++i) {
    const double f = s.frequency_hz(i);
    nlohmann::json jm = {{"mode", i + 1}, {"frequency_hz", f}, {"omega", r.omega[i]}, {"kind", to_string(r.kind[i])},
                         {"index_of_kind", s.index_of_kind[i]}, {"uncertainty", r.uncertainty[i]}};
    std::string extra;
    if (s.has_reference) {
      const ModeReference& ref = s.reference[i];
      jm["reference_hz"] = ref.reference_hz;
      jm["reference_theory"] = ref.theory;
      jm["relative_error"] = ref.relative_error;
      std::string eb = "-";
      if (ref.euler_bernoulli_hz) {
        jm["euler_bernoulli_hz"] = *ref.euler_bernoulli_hz;
        eb = fmt::format("{:.6f}", *ref.euler_bernoulli_hz);
      }
      extra = fmt::format(" {:>11.6f} {:<4} {:>+9.4f}% {:>16}", ref.reference_hz, ref.theory == "Timoshenko" ? "(T)" : "(rod)",
                          100.0 * ref.relative_error, eb);
    }
    modes.push_back(jm);
    if (!c.json)
      fmt::print("{:>4} {:>14.6f} {:>14.6f} {:>12}{}\n", i + 1, f, r.omega[i],
                 fmt::format("{}{}", to_string(r.kind[i]), s.index_of_kind[i]), extra);
  }
  for (const auto& w : s.warnings) print_warning(w);
  if (!o.output.empty() && !c.json) fmt::print("mode shapes in {}\n", o.output);
  if (!c.json && s.has_reference)
    fmt::print("reference: (T) Timoshenko cantilever (shear and rotary inertia), (rod) rod theory; the error is "
               "the discretisation's and falls as 1/n²\n");
  if (acc && !o.output.empty()) write_accuracy(o.output, *acc);
  if (c.json) {
    nlohmann::json out = {{"command", "modes"}, {"case", cs.path}, {"n", model.n()}, {"solver", r.dense ? "dense" : "lanczos"},
                          {"free_joints", s.free_names}, {"modes", modes}};
    if (acc) out["accuracy"] = accuracy_json(*acc);
    print_json(out);
  } else if (acc) {
    print_accuracy(*acc);
  }
  return acc && !acc->met ? 3 : 0;  // (a target that was not met is not success)
}

}  // namespace rfem::app
