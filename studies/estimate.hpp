#pragma once
// Whether a run can be afforded before it starts: its memory against what the machine has, and
// for large runs the timed cost of a step.
#include "../cases/case_file.hpp"
#include "../solvers/integrator.hpp"

namespace rfem {

/// MemAvailable of /proc/meminfo [B]; infinity where it cannot be read.
double available_memory();

/// Refuses (CaseError naming link.n) a run of `model` whose estimated memory exceeds the memory
/// available now; with `time` (the program does so from kLargeRunRfes rfes on) also times one
/// residual evaluation and one Newton setup.
RunEstimate check_affordable(const Case& cs, std::shared_ptr<const Model> model, const std::vector<JointInput>& inputs,
                             int threads, bool time);

}  // namespace rfem
