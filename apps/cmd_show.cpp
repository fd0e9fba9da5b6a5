// `rfem show`: the assembled tree of a case, to check it against its drawing.
#include <fmt/core.h>

#include "commands.hpp"
#include "../studies/show.hpp"

namespace rfem::app {

int run_show(const Common& c) {
  const Case cs = read_checked_case(c);
  const ModelSummary s = show_model(cs, c.n);
  if (!c.json) {
    fmt::print("{}", format_summary(s));
    return 0;
  }
  nlohmann::json entries = nlohmann::json::array();
  for (const TreeEntry& e : s.entries)
    entries.push_back({{"kind", e.kind}, {"name", e.name}, {"depth", e.depth}, {"parent", e.parent}, {"where", e.where},
                       {"mass", e.mass}, {"length", e.length}, {"rfes", e.rfes}, {"detail", e.detail},
                       {"coordinates", e.coordinates}});
  nlohmann::json frames = nlohmann::json::array();
  for (const TreeEntry& f : s.frames) frames.push_back({{"name", f.name}, {"parent", f.parent}, {"where", f.where}});
  print_json({{"command", "show"}, {"case", cs.path}, {"n", s.n}, {"m", s.m}, {"dof", s.dof}, {"unknowns", s.unknowns},
              {"mass", s.mass}, {"entries", entries}, {"urdf", s.urdf}, {"frames", frames}});
  return 0;
}

}  // namespace rfem::app
