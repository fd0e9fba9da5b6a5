#pragma once
// The scalar quantities of a refinement study, typed (README, "Quantities", has the table):
//   static and modal:  [LINK/]tip:ux|uy|uz|rx|ry|rz     static tip of a link (default: the last)
//                      mode:K, axial:K, bending-y:K, bending-z:K, torsion:K   K-th frequency [Hz]
//                      linear:K             K-th frequency [Hz] of the linear model about rest
//                                           (studies/linearize.hpp: free joints move with it)
//   dynamic:           AGG:SERIES[WINDOW]   AGG = peak (max |x|), max, min, rms, mean over the run
//                                            or over WINDOW = [t1:t2] (times in s)
//                      SERIES@T             the value at output time T
//   SERIES = TERM or TERM-TERM (a difference of two runs' series at the same times), and
//   TERM = [RUN/][LINK/]NAME with NAME = u1, u2, theta (a link's tip deflections) or tauJ, qJ, vJ, aJ
//   (torque, coordinate, rate, acceleration of joint J from 1); RUN defaults to the procedure's
//   main run (kinematic for the paper's, run for a single one). Fig. 6's point, the torque the
//   flexibility adds, is peak:kinematic/tau3-rigid/tau3.
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "../simulation/common.hpp"
#include "../solvers/equations.hpp"
#include "runs.hpp"

namespace rfem {

/// One series a dynamic quantity reads from a run.
struct QuantityTerm {
  std::string run;      ///< run, rigid, kinematic, force
  int link = -1;        ///< tip deflections: the link (−1: the last)
  int component = 0;    ///< tip deflections: 0 u1, 1 u2, 2 θ
  int joint = -1;       ///< joint series: the joint (1-based); −1: a tip deflection
  char joint_value = 0; ///< 't' torque, 'q' coordinate, 'v' rate, 'a' acceleration
  bool operator==(const QuantityTerm& o) const {
    return run == o.run && link == o.link && component == o.component && joint == o.joint && joint_value == o.joint_value;
  }
};

struct Quantity {
  enum class Kind {
    Tip,         ///< static tip component `component` (0–5) of link `link`
    Mode,        ///< the K-th frequency
    ModeOfKind,  ///< the K-th frequency of kind `mode_kind`
    LinearMode,  ///< the K-th frequency of the linear model about rest (rfem linearize)
    Aggregate,   ///< `aggregate` of the series over [t1, t2]
    AtTime,      ///< the series at output time `time`
  };
  enum class Aggregate { Peak, Max, Min, Rms, Mean };
  std::string text;       ///< as given
  Kind kind = Kind::Tip;
  int link = -1;          ///< Tip: the link (−1: the last)
  int component = 0;      ///< Tip: 0–5
  int mode = 0;           ///< Mode, ModeOfKind: K ≥ 1
  std::string mode_kind;  ///< ModeOfKind: axial, bending-y, bending-z, torsion
  Aggregate aggregate = Aggregate::Peak;
  std::vector<QuantityTerm> terms;  ///< dynamic: one, or two (the first minus the second)
  double time = -1.0;               ///< AtTime [s]
  double t1 = 0.0, t2 = 0.0;        ///< Aggregate: the window [s] (the whole run by default)
  bool dynamic() const { return kind == Kind::Aggregate || kind == Kind::AtTime; }
};

/// Parses and checks a quantity against the case (a T off the output grid, a window outside the
/// run, an unknown run, link or joint): CaseError with a one-line message.
Quantity parse_quantity(const Case& cs, const std::string& text);
/// A static or modal quantity at n rfes.
/// `free`: joints that move with a modal quantity's modes (`rfem modes --free`: numbers from 1, names, "base").
double evaluate_quantity(const Case& cs, int n, const Quantity& q, const JointRate& rate = {},
                         const std::vector<std::string>& free = {});
/// The same from its text.
double evaluate_quantity(const Case& cs, int n, const std::string& text, const JointRate& rate = {});
/// A term's value in one output sample of its run.
double term_value(const Model& model, const QuantityTerm& term, const OutputSample& s);
/// A dynamic quantity from its terms' series (`series[i]` of terms[i], sampled at `times`).
double dynamic_value(const Quantity& q, const std::vector<double>& times, const std::vector<std::vector<double>>& series);
/// The runs the quantities read (what a study must run).
std::vector<std::string> runs_read(const std::vector<Quantity>& qs);

/// Records, per run it observes (named `prefix` + run), the output times and every series the
/// dynamic quantities read; values() gives them (NaN for a quantity that is not dynamic or whose
/// run was not observed).
class QuantityRecorder : public RunObserver {
 public:
  QuantityRecorder(const std::vector<Quantity>& qs, std::string prefix = "");
  void begin(const RunInfo& info) override;
  void sample(const OutputSample& s) override;
  std::vector<double> values() const;
  // (its series so far go into a run's checkpoint: a resumed study evaluates the same values)
  std::string state_key() const override { return "quantities"; }
  std::vector<double> save() const override;
  void restore(const std::vector<double>& x) override;

 private:
  std::vector<Quantity> qs_;
  std::string prefix_, run_;
  std::shared_ptr<const Model> model_;
  std::vector<QuantityTerm> terms_;
  std::vector<std::vector<double>> series_;
  std::map<std::string, std::vector<double>> times_;
};

}  // namespace rfem
