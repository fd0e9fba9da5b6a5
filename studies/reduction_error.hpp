#pragma once
// The reduction's error of a run (docs/accuracy.md, "The reduction's error"): a reduced link's
// error lives in the modes it leaves out (docs/formulation.md §9), the bending modes above the m-th,
// which a coarse discretisation already resolves. So the full and the reduced model run the same
// procedure at a coarse n beside the run, and the difference of their peaks is the estimate of the
// run's (docs/accuracy.md: 0.98–0.99 of the true error on Kane's spin-up; its limits).
#include <string>
#include <vector>

#include "../core/model.hpp"
#include "../solvers/reduction.hpp"
#include "accuracy.hpp"
#include "runs.hpp"

namespace rfem {

class ResultsWriter;

/// The coarse n of the companion runs for a model of n rfes: n / kCompanionShare, raised until
/// every reduced link has at least kCompanionModes × its modes of rotations to choose from (3 per
/// rfe), at most n.
int companion_n(const Case& cs, const Model& model);
/// Half of n: a quarter missed the paper's force θ with 4 modes 11 times over at n = 60 (its higher
/// modes, off by 10–50 % at n = 15, change order), half keeps every error above 1e-4 of a peak within
/// a factor of 2 (docs/accuracy.md, "The reduction's error").
inline constexpr int kCompanionShare = 2;
inline constexpr int kCompanionModes = 3;


/// Fills every completed run's reduction_error and reduction_n (runs as run_case returned them on
/// `model`, with request `rq`): the procedure's runs (not the paper's rigid one) on the full and the
/// reduced model at companion_n, with rq's threads, stop token and progress (names prefixed
/// "reduction check/…"). Warns through rq.warn, one line per run, where an estimate exceeds
/// rq.reduction_allowed of its peak (u1 and u2 against the larger of the two). Nothing if the model
/// has no reduced link, a run did not complete or a companion does not (stopped: no estimate).
void estimate_reduction_error(const Case& cs, const Model& model, const RunRequest& rq, std::vector<RunResult>& runs);

/// Writes the runs' estimates into an open results file: table `reduction_error`, a row per run and
/// link (attribute rows: "force/link"), columns peak_u1, peak_u2, peak_theta, error_u1, error_u2,
/// error_theta; attribute n (the companion n). Nothing if no run has one.
void write_reduction_error(ResultsWriter& file, const std::vector<RunResult>& runs);

/// Adds the runs' reduction estimates to a target's error bars (`peak:RUN/[LINK/]u1` …): the
/// estimate's magnitude as error_reduction, into error, and met and shortfall updated.
void add_reduction_error(AccuracyResult& a, const std::vector<RunResult>& runs);

}  // namespace rfem
