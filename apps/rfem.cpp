// rfem: the command-line program. See README.md for every command and its output.
#include <CLI/CLI.hpp>
#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/spdlog.h>
#include <fmt/core.h>
#include <omp.h>

#include <Eigen/Core>
#include <sstream>

#include "apps/commands.hpp"

int main(int argc, char** argv) {
  using namespace rfem::app;
  CLI::App app{"rfem: dynamics of manipulators with flexible links by the Rigid Finite Element Method"};
  app.set_version_flag("--version", std::string("rfem ") + RFEM_VERSION);
  app.require_subcommand(1);
  Common common;
  app.add_option("--threads", common.threads, "OpenMP threads for assembly (default: all cores)")
      ->check(CLI::PositiveNumber);
  auto add_common = [&](CLI::App* sub) {
    sub->add_option("case", common.case_path, "case file (TOML)")->required();
    sub->add_option("--set", common.overrides, "override a case value: key.path=value (repeatable)");
    sub->add_option("--n", common.n, "number of rfes, distributed over the segments by length")
        ->check(CLI::PositiveNumber);
    sub->add_flag("--json", common.json, "print results as JSON");
    sub->add_flag("-q,--quiet", common.quiet, "no progress line or summary");
    sub->add_flag("-v,--verbose", common.verbose, "log solver events to stderr");
  };
  ModesOptions mo;
  auto add_rate = [&](CLI::App* sub) {
    sub->add_option("--rate", mo.rate, "steady rate of the chosen joint [rad/s]")->each([&](const std::string&) {
      mo.rate_given = true;
    });
    sub->add_option("--joint", mo.joint, "joint (1-based) that --rate applies to")->check(CLI::PositiveNumber);
  };

  auto* st = app.add_subcommand("static", "static equilibrium under gravity and tip loads, joints held");
  add_common(st);
  auto* md = app.add_subcommand("modes", "natural frequencies and mode shapes of the flexible link, base held");
  add_common(md);
  md->add_option("--count", mo.count, "number of modes")->check(CLI::PositiveNumber);
  add_rate(md);
  auto* rn = app.add_subcommand("run", "time integration of the case's [simulation]; results to HDF5");
  add_common(rn);
  std::string output;
  rn->add_option("-o,--output", output, "results file (default: the case name with .h5, here)");
  auto* pl = app.add_subcommand("plot", "PNG figures of a results file (the paper's Figures 5-8, runs, refinement)");
  std::string plot_file, plot_dir;
  pl->add_option("results", plot_file, "results file (HDF5) from rfem run or rfem refine")->required();
  pl->add_option("-o,--output", plot_dir, "directory for the PNG files (default: beside the results file)");
  auto* rf = app.add_subcommand("refine", "convergence table of a quantity over a series of n");
  add_common(rf);
  std::string ns_text = "5,10,20,40,80", quantity = "mode:1";
  rf->add_option("--ns", ns_text, "comma-separated list of n (alias of --n for refine)");
  rf->add_option("--quantity", quantity,
                 "static tip:ux|uy|uz|rx|ry|rz; modes mode:K, bending-y:K, bending-z:K, axial:K, torsion:K; "
                 "dynamic [RUN/]peak:u1|u2|theta, [RUN/]u1@T, u2@T, theta@T, tauJ@T, qJ@T");
  std::string refine_output;
  rf->add_option("-o,--output", refine_output, "HDF5 file for every run and the table (default for dynamic quantities: CASE_refine.h5)");
  add_rate(rf);
  // refine takes a list in --n: reroute it before parsing.
  for (int i = 1; i + 1 < argc; ++i)
    if (std::string(argv[i]) == "refine")
      for (int k = i + 1; k + 1 < argc; ++k)
        if (std::string(argv[k]) == "--n") argv[k] = const_cast<char*>("--ns");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  if (common.threads > 0) omp_set_num_threads(common.threads);
  Eigen::setNbThreads(1);  // we parallelise ourselves
  spdlog::set_default_logger(spdlog::stderr_logger_mt("rfem"));
  spdlog::set_pattern("[%H:%M:%S.%e] %v");
  spdlog::set_level(common.verbose ? spdlog::level::debug : spdlog::level::warn);
  try {
    if (st->parsed()) return run_static(common);
    if (md->parsed()) return run_modes(common, mo);
    if (pl->parsed()) return run_plot(plot_file, plot_dir);
    if (rn->parsed()) {
      if (output.empty()) {
        std::string stem = common.case_path.substr(common.case_path.find_last_of('/') + 1);
        output = stem.substr(0, stem.rfind('.')) + ".h5";
      }
      return run_simulation(common, output);
    }
    if (rf->parsed()) {
      std::vector<int> ns;
      std::stringstream ss(ns_text);
      for (std::string t; std::getline(ss, t, ',');) {
        try {
          ns.push_back(std::stoi(t));
        } catch (...) {
          throw rfem::CaseError("--n: '" + t + "' is not an integer");
        }
        if (ns.back() < 1) throw rfem::CaseError("--n: every n must be positive");
      }
      if (ns.size() < 2) throw rfem::CaseError("--n: refine needs at least two values");
      return run_refine(common, ns, quantity, mo, refine_output);
    }
  } catch (const rfem::CaseError& e) {
    fmt::print(stderr, "rfem: error: {}\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    fmt::print(stderr, "rfem: error: {}\n", e.what());
    return 1;
  }
  return 0;
}
