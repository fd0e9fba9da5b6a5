// Example 6: rfem from C++, against the installed library (find_package(rfem) -> rfem::rfem).
//
// (1) A refinement study written by hand: Kane's cantilever under a tip load at n = 10, 20, 40 —
//     the static tip deflection converges with order 2 to P L³/3EI + P L/κGA.
// (2) The paper's deployment, its kinematic run only, results in memory and in an HDF5 file; a
//     progress callback, and a stop token that a second run uses to stop itself half-way.
//
//     ex6_library CASES_DIR [OUT.h5]        (CASES_DIR: the repository's cases/; ~1 s)
#include <cmath>
#include <cstdio>
#include <string>

#include "rfem/simulation/recorders.hpp"
#include "rfem/solvers/beam_theory.hpp"
#include "rfem/studies/runs.hpp"
#include "rfem/studies/static_study.hpp"

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s CASES_DIR [OUT.h5]\n", argv[0]);
    return 2;
  }
  const std::string cases = argv[1], out = argc > 2 ? argv[2] : "ex6_paper.h5";
  try {
    // 1. The tip deflection of Kane's beam under 1 N along z, against beam theory.
    const rfem::Case beam = rfem::with_overrides(rfem::read_case(cases + "/kane_beam.toml"), {"loads.tip_force=[0, 0, -1.0]"});
    const rfem::Segment& s = beam.links[0].link.segments[0];
    const double exact = -rfem::beam::cantilever_tip_deflection(s, 1.0, true);
    double previous = NAN, change = NAN;
    for (int n : {10, 20, 40}) {
      const rfem::StaticStudy st = rfem::static_study(beam, n);
      const double uz = st.tips[0].motion[2];
      const double d = uz - previous;
      std::printf("n = %2d: tip uz = %.9e m, error %.3e m", n, uz, uz - exact);
      if (std::isfinite(change)) std::printf(", observed order %.3f", std::log2(change / d));  // n doubles
      std::printf("\n");
      change = d;
      previous = uz;
    }
    std::printf("beam theory P L^3/3EI + P L/kGA = %.9e m\n", exact);

    // 2. The paper's kinematic run at n = 12: peaks in memory, series in an HDF5 file.
    const rfem::Case paper = rfem::read_case(cases + "/paper_deployment.toml");
    rfem::ResultsWriter file(out, rfem::describe(paper, "ex6_library", "paper", 12, 1));
    rfem::Hdf5Recorder recorder(file);
    rfem::RunRequest rq;
    rq.n = 12;
    rq.threads = 1;
    rq.runs = {rfem::RunName::Kinematic};
    rq.observers = {&recorder};
    long beats = 0;
    rq.progress = [&](const rfem::Progress&) { ++beats; };
    const std::vector<rfem::RunResult> runs = rfem::run_case(paper, rq);
    file.close();
    const rfem::RunResult& k = runs.at(0);
    std::printf("%s: %s, %ld outputs; peak |u1| = %.6e m, |u2| = %.6e m, |theta| = %.6e rad\n", k.name.c_str(),
                k.status.to_string().c_str(), k.samples, k.peaks[0].u1, k.peaks[0].u2, k.peaks[0].theta);
    const rfem::Table tau = k.series->table("joint_tau");
    double peak3 = 0.0;
    for (long i = 0; i < tau.rows; ++i) peak3 = std::max(peak3, std::abs(tau.at(i, 2)));
    std::printf("peak joint-3 torque %.6e N m; progress reported: %s\n", peak3, beats > 0 ? "yes" : "no");

    // 3. A run that stops itself at t = 10 s: interrupted, every output up to there kept.
    rq.observers.clear();
    rq.progress_interval = 0.0;  // at every step
    rq.progress = [&](const rfem::Progress& p) {
      if (p.t >= 10.0) rq.stop.request();
    };
    const rfem::RunResult half = rfem::run_case(paper, rq).at(0);
    std::printf("%s: %s after t = %.2f s\n", half.name.c_str(), half.status.to_string().c_str(), half.t_reached);
  } catch (const std::exception& e) {  // a CaseError names file, line and key
    std::fprintf(stderr, "ex6_library: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
