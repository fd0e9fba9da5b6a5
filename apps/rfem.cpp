// rfem: the command-line program. See README.md for every command and its output.
#include <CLI/CLI.hpp>
#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/spdlog.h>
#include <fmt/core.h>

#include <cmath>
#include <sstream>

#include <csignal>

#include <omp.h>

#include "commands.hpp"
#include "../assembly/workspace.hpp"
#include "../results/errors.hpp"
#include "rfem/version.hpp"

namespace {

// Positive integers up to `max` only, with a message that says so (CLI11's range check prints the
// largest double). Runs on the text, before any conversion.
CLI::Validator positive_int(long max) {
  return CLI::Validator(
      [max](std::string& s) -> std::string {
        size_t used = 0;
        long v = 0;
        try {
          v = std::stol(s, &used);
        } catch (...) {
          used = 0;
        }
        if (used == 0 || used != s.size() || v < 1 || v > max)
          return "must be a positive integer up to " + std::to_string(max) + " (got '" + s + "')";
        return "";
      },
      "POSITIVE");
}
const CLI::Validator kPositiveInt = positive_int(100000000);
// The whole text as a finite number, or NaN.
double finite_number(const std::string& s) {
  size_t used = 0;
  double v = NAN;
  try {
    v = std::stod(s, &used);
  } catch (...) {
    used = 0;
  }
  return used == 0 || used != s.size() || !std::isfinite(v) ? NAN : v;
}
// A finite number ≥ 0 (CLI11's NonNegativeNumber lets "nan" through).
const CLI::Validator kNonNegativeFinite(
    [](std::string& s) -> std::string {
      return finite_number(s) >= 0 ? "" : "must be a finite number, 0 or more (got '" + s + "')";
    },
    "NONNEGATIVE");
const CLI::Validator kRfes = positive_int(rfem::kMaxRfes);  // the case file's own limit
// A finite number > 0 of seconds (--max-time).
const CLI::Validator kPositiveSeconds(
    [](std::string& s) -> std::string {
      return finite_number(s) > 0 ? "" : "must be a positive number of seconds (got '" + s + "')";
    },
    "SECONDS");

}  // namespace

int main(int argc, char** argv) {
  using namespace rfem::app;
  rfem::disable_hdf5_exit_cleanup();  // (every results file is closed before main returns)
  std::signal(SIGXFSZ, SIG_IGN);      // a file size limit (ulimit -f) is a write error, reported, not a kill
  CLI::App app{"rfem: dynamics of manipulators with flexible links by the Rigid Finite Element Method"};
  app.set_version_flag("--version", std::string("rfem ") + rfem::version_string);
  app.require_subcommand(1);
  app.fallthrough();  // global options (--threads) also after the subcommand
  Common common;
  for (int i = 0; i < argc; ++i) common.command_line += (i ? " " : "") + std::string(argv[i]);
  app.add_option("--threads", common.threads,
                 "OpenMP threads (default: all cores, each run timing one thread against all and keeping the faster)")
      ->check(kPositiveInt);
  auto add_common = [&](CLI::App* sub, bool single_n) {
    sub->add_option("case", common.case_path, "case file (TOML)")->required();
    sub->add_option("--set", common.overrides, "override a case value: key.path=value (repeatable)");
    if (single_n)
      sub->add_option("--n", common.n, "number of rfes, distributed over the segments by length")->check(kRfes);
    sub->add_flag("--json", common.json, "print results as JSON");
    sub->add_flag("-q,--quiet", common.quiet, "no progress line or summary");
    sub->add_flag("-v,--verbose", common.verbose, "log solver events to stderr");
  };
  // A target instead of an n (studies/accuracy.hpp): run, modes, static, refine.
  auto add_accuracy = [&](CLI::App* sub) {
    sub->add_option("--accuracy", common.accuracy,
                    "a target instead of an n: a relative error bar every reported value must meet (1e-3), or "
                    "QUANTITY=ERROR for one value (peak:u1=2e-4); repeatable; rfem chooses n and the tolerances")
        ->delimiter(',');
    sub->add_option("--max-n", common.max_n, fmt::format("the largest n a target may reach (default {})", rfem::kMaxTargetN))
        ->check(kRfes);
    sub->add_option("--max-time", common.max_time,
                    "wall time a command with a target may take [s]: its ladder stops before an n predicted to end past it "
                    "(default: none)")
        ->check(kPositiveSeconds);
  };
  ModesOptions mo;
  auto add_rate = [&](CLI::App* sub) {
    sub->add_option("--rate", mo.rate.rate, "steady rate of the chosen joint [rad/s or m/s]")->each([&](const std::string&) {
      mo.rate.given = true;
    });
    sub->add_option("--joint", mo.rate.joint, "joint (1-based) that --rate applies to")->check(kPositiveInt);
  };

  auto* sh = app.add_subcommand("show", "the assembled tree: joints, links, payloads, what each sits on, masses, coordinates, inputs");
  add_common(sh, true);
  auto* st = app.add_subcommand("static", "static equilibrium under gravity and tip loads, joints held (or turning steadily: --rate)");
  add_common(st, true);
  add_accuracy(st);
  add_rate(st);
  auto* md = app.add_subcommand("modes", "natural frequencies and mode shapes of the flexible link, base held or joints free");
  add_common(md, true);
  add_accuracy(md);
  md->add_option("--count", mo.count, "number of modes (at most 6n + free joints)")->check(kPositiveInt);
  md->add_option("-o,--output", mo.output, "HDF5 file for the frequencies and mode shapes (group modes)");
  md->add_option("--free", mo.free, "joints that move with the modes: numbers from 1, names, or 'base' (a free base's six)")
      ->delimiter(',');
  add_rate(md);
  auto* rn = app.add_subcommand("run", "time integration of the case's [simulation]; results to HDF5");
  add_common(rn, true);
  add_accuracy(rn);
  RunOptions run_options;
  run_options.checkpoint = rfem::kCheckpointInterval;
  rn->add_option("-o,--output", run_options.output, "results file (default: the case name with .h5, here)");
  rn->get_option("case")->required(false);
  rn->add_option("--resume", run_options.resume,
                 "continue the runs an interrupted or killed rfem run left in this results file, from their last "
                 "checkpoints (no case: the file has it)")
      ->excludes(rn->get_option("case"))
      ->excludes(rn->get_option("--set"))
      ->excludes(rn->get_option("--n"))
      ->excludes(rn->get_option("-o"))
      ->excludes(rn->get_option("--accuracy"));
  rn->add_option("--checkpoint", run_options.checkpoint,
                 fmt::format("seconds of wall time between checkpoints (0: none; default {:g})", rfem::kCheckpointInterval))
      ->check(kNonNegativeFinite);
  rn->add_flag("--no-reduction-check", run_options.no_reduction_check,
               "with reduced links: skip the full and reduced runs at a coarse n that estimate the reduction's error");
  auto* pl = app.add_subcommand("plot", "PNG figures of a results file (the paper's Figures 5-8, runs, refinement)");
  std::string plot_file, plot_dir;
  pl->add_option("results", plot_file, "results file (HDF5) from rfem run or rfem refine")->required();
  pl->add_option("-o,--output", plot_dir, "directory for the figures (default: beside the results file)");
  std::string plot_format;
  bool paper_signs = false;
  pl->add_option("--format", plot_format, "png (default), pdf or svg")->check(CLI::IsMember({"png", "pdf", "svg"}));
  pl->add_flag("--paper-signs", paper_signs, "u1, u2 with the paper's (Kane's) sign, the opposite of the physical displacement");
  auto* vw = app.add_subcommand("view", "ParaView (XDMF) files of a results file's runs that stored their poses");
  std::string view_file;
  std::vector<std::string> view_runs;
  vw->add_option("results", view_file, "results file (HDF5) from rfem run with simulation.store_flexible_every > 0")->required();
  vw->add_option("--run", view_runs, "only these runs (default: every run with poses)")->delimiter(',');
  auto* an = app.add_subcommand("animate", "the arm moving (MP4 with ffmpeg, or GIF) from a run that stored its poses");
  std::string anim_file, anim_out, anim_run, anim_view;
  double anim_scale = 0;
  int anim_fps = 0, anim_frames = 0;
  an->add_option("results", anim_file, "results file (HDF5) from rfem run with simulation.store_flexible_every > 0")->required();
  an->add_option("-o,--output", anim_out, "FILE.mp4 or FILE.gif (default: RESULT.RUN.mp4, .gif without ffmpeg)");
  an->add_option("--run", anim_run, "run (default: the last one with poses)");
  an->add_option("--scale", anim_scale, "deflection magnification (default: the peak drawn at 10% of the arm)")->check(CLI::PositiveNumber);
  an->add_option("--view", anim_view, "3d (default), xy, xz or yz")->check(CLI::IsMember({"3d", "xy", "xz", "yz"}));
  an->add_option("--fps", anim_fps, "frames per second (default 25)")->check(kPositiveInt);
  an->add_option("--frames", anim_frames, "at most this many frames, the stored steps thinned evenly (default 300)")->check(kPositiveInt);
  auto* bd = app.add_subcommand("bode", "the Bode plot of a linear model file (rfem linearize -o) from a joint's torque to an output");
  std::string bode_file, bode_in, bode_out, bode_fig;
  bd->add_option("linear", bode_file, "linear model file (HDF5) from rfem linearize")->required();
  bd->add_option("--input", bode_in, "a free joint (the torque added there)")->required();
  bd->add_option("--output", bode_out, "an output: LINK/tip_u1, JOINT/q, a sensor column, …")->required();
  bd->add_option("-o,--out", bode_fig, "the figure (default: LIN.INPUT.OUTPUT.png beside the file; .pdf, .svg by extension)");
  auto* rf = app.add_subcommand("refine", "convergence tables of quantities over a series of n");
  add_common(rf, false);
  RefineOptions ro;
  rf->add_option("--n", ro.ns, "the series of n, increasing: --n 6,12,24 (with --accuracy: where it starts)")->delimiter(',')->check(kRfes);
  add_accuracy(rf);
  rf->add_option("--quantity", ro.quantities,
                 "one or more (comma-separated, from the same runs): static tip:ux|uy|uz|rx|ry|rz; modes mode:K, "
                 "bending-y:K, bending-z:K, axial:K, torsion:K; dynamic [RUN/]peak:u1|u2|theta, [RUN/]u1@T, u2@T, "
                 "theta@T, tauJ@T, qJ@T")
      ->delimiter(',')
      ->required();
  rf->add_option("-o,--output", ro.output, "HDF5 file for every run and the tables (default for dynamic quantities: CASE_refine.h5)");
  rf->add_option("--modes", ro.modes,
                 "a series over modes instead of n: every flexible link reduced to m modes (link.modes), increasing, "
                 "at the one --n, each against the full model: --modes 4,8,16")
      ->delimiter(',');
  bool no_check = false;
  rf->add_flag("--no-integration-check", no_check,
               "do not rerun the finest n at 100x tighter tolerances to estimate the integration error");
  add_rate(rf);
  auto* ln = app.add_subcommand("linearize", "the linear model M, D, K, B, C and A, B, C, D about the initial equilibrium or a saved state");
  add_common(ln, true);
  add_accuracy(ln);
  LinearizeOptions lo;
  ln->add_option("-o,--output", lo.output, "HDF5 file for the matrices (group linear)")->required();
  ln->add_option("--state", lo.state, "about this saved simulation state (rfem.SimulationState.save; default: the initial equilibrium)");
  ln->add_flag("--on-motion", lo.on_motion, "with the state's own accelerations (default: at rest, the inputs that hold it in u0)");
  ln->add_flag("--dense", lo.dense, "difference the equations column by column (the reference: 9 evaluations per state) instead of the sparse method");
  auto* sw = app.add_subcommand("sweep", "a parameter sweep: one run per point, quantities per run, one index (--jobs, or under mpirun)");
  SweepOptions so;
  bool sweep_json = false, sweep_quiet = false;
  sw->add_option("sweep", so.path, "sweep file (TOML): [sweep] case, quantities; [parameters] key = [values]")->required();
  sw->add_option("-o,--output", so.output, "index file (default: [sweep] output, or the sweep file's name with .h5, here)");
  sw->add_option("--jobs", so.jobs, "runs at once on this machine, one thread each (default: the cores)")->check(kPositiveInt);
  sw->add_flag("--retry-failed", so.retry_failed, "run the points that failed before again (default: keep their reason)");
  sw->add_flag("--json", sweep_json, "the table as JSON on stdout");
  sw->add_flag("-q,--quiet", sweep_quiet, "no progress line and no table");

  // A first word that is neither an option nor a command (CLI11 would only say one is required).
  if (argc > 1 && argv[1][0] != '-') {
    const std::string w = argv[1];
    bool known = false;
    for (const auto* sub : app.get_subcommands([](const CLI::App*) { return true; })) known |= sub->get_name() == w;
    if (!known) {
      print_line(fmt::format("rfem: error: unknown command '{}' (show, static, modes, linearize, bode, run, refine, sweep, plot, view, animate; rfem --help)", w));
      return 2;
    }
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // The README's rule for bad input: one line, exit code 2.
    std::string what = e.what();
    for (char& ch : what)
      if (ch == '\n') ch = ' ';
    print_line(fmt::format("rfem: error: {} (rfem --help)", what));
    return 2;
  }
  // librfem parallelises itself (--threads goes to each call; Eigen's products are serial,
  // EIGEN_DONT_PARALLELIZE), and no call the program makes uses more than --threads, whether it is
  // passed them or not.
  if (common.threads > 0) omp_set_num_threads(common.threads);
  // More threads than cores: said once (an MPI sweep's ranks are counted where they run).
  if (common.threads > 0)
    if (const std::string w = rfem::oversubscription(1, common.threads, "--threads " + std::to_string(common.threads)); !w.empty())
      print_warning(w);
  spdlog::set_default_logger(spdlog::stderr_logger_mt("rfem"));
  spdlog::set_pattern("[%H:%M:%S.%e] %v");
  spdlog::set_level(common.verbose ? spdlog::level::debug : spdlog::level::warn);
  try {
    if (sh->parsed()) return run_show(common);
    if (st->parsed()) return run_static(common, mo);
    if (md->parsed()) return run_modes(common, mo);
    if (ln->parsed()) return run_linearize(common, lo);
    if (bd->parsed()) {
      std::vector<std::string> args{bode_file, "--input", bode_in, "--output", bode_out};
      if (!bode_fig.empty()) args.insert(args.end(), {"-o", bode_fig});
      return run_bode(args);
    }
    if (pl->parsed()) return run_plot(plot_file, plot_dir, plot_format, paper_signs);
    if (vw->parsed()) return run_view(view_file, view_runs);
    if (an->parsed()) {
      std::vector<std::string> args{anim_file};
      if (!anim_out.empty()) args.insert(args.end(), {"-o", anim_out});
      if (!anim_run.empty()) args.insert(args.end(), {"--run", anim_run});
      if (anim_scale > 0) args.insert(args.end(), {"--scale", fmt::format("{}", anim_scale)});
      if (!anim_view.empty()) args.insert(args.end(), {"--view", anim_view});
      if (anim_fps > 0) args.insert(args.end(), {"--fps", std::to_string(anim_fps)});
      if (anim_frames > 0) args.insert(args.end(), {"--frames", std::to_string(anim_frames)});
      return run_animate(args);
    }
    if (rn->parsed()) {
      if (run_options.resume.empty() && common.case_path.empty())
        throw rfem::CaseError("run: a case file (or --resume RESULTS.h5) is required");
      if (run_options.output.empty() && run_options.resume.empty()) {
        std::string stem = common.case_path.substr(common.case_path.find_last_of('/') + 1);
        run_options.output = stem.substr(0, stem.rfind('.')) + ".h5";
      }
      return run_simulation(common, run_options);
    }
    if (sw->parsed()) return run_sweep_command(so, sweep_json, sweep_quiet);
    if (rf->parsed()) {
      ro.integration_check = !no_check;
      return run_refine(common, ro, mo);
    }
  } catch (const rfem::CaseError& e) {
    print_line(fmt::format("rfem: error: {}", e.what()));
    return 2;
  } catch (const rfem::ResultsError& e) {  // a results file that cannot be made or written: the caller's path
    print_line(fmt::format("rfem: error: {}", e.what()));
    return 2;
  } catch (const std::exception& e) {
    print_line(fmt::format("rfem: error: {}", e.what()));
    return 1;
  }
  return 0;
}
