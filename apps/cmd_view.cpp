// `rfem view`: ParaView (XDMF) files for the runs of a results file that stored their poses.
#include <fmt/core.h>

#include "commands.hpp"
#include "../results/xdmf.hpp"

namespace rfem::app {

int run_view(const std::string& results, const std::vector<std::string>& runs) {
  std::vector<std::string> written;
  try {
    written = write_xdmf(results, runs);
  } catch (const ResultsError& e) {
    throw CaseError(e.what());  // a file without poses is the user's input: exit 2
  }
  for (const std::string& x : written) fmt::print("ParaView: {}\n", x);
  return 0;
}

}  // namespace rfem::app
