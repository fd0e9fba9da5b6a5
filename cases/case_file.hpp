#pragma once
// Case files: human-edited TOML describing materials, sections, the flexible links' segments and
// discretisation, the joints and their rigid bodies, what each is mounted on, gravity and loads.
// Every key is checked; a bad file raises CaseError with a one-line "file:line: key: what is wrong"
// message. A case is a value: read from a file or from TOML text, changed with the paths of
// `rfem --set` (read and checked again), copied freely. The format is documented in README.md
// ("Case files").
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "../core/model.hpp"
#include "../solvers/integrator.hpp"
#include "../solvers/statics.hpp"
#include "accuracy_spec.hpp"
#include "names.hpp"
#include "sensor_spec.hpp"

namespace rfem {

class CaseError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The most rfes a link, a segment or a whole model may have (`n`, `parts`, `--n`, Python's `n`):
/// far beyond memory, it guards int overflow and an allocation that cannot succeed.
inline constexpr long kMaxRfes = 10000000;

/// A joint's input in a time integration (`joints[].input`); the kinds are documented in README.md.
struct InputSpec {
  InputKind kind = InputKind::Torque;
  double alpha = 0, T = 0, Omega = 0, rate = 0, value = 0;
  std::string file;  ///< table or results file, resolved relative to the case file
  std::string run;   ///< group in a results file
  int joint = 0;     ///< joint (1-based) of the results file; 0: the same joint
  std::string where; ///< "file:line: joints.i.input" for later error messages
  /// kind = "pd": τ = τ_ff + kp (q_ref − q) + kd (q̇_ref − q̇) on the reference motion (one of the
  /// prescribed kinds, from the joint's value); feedforward "none" or "rigid" (computed torque).
  std::shared_ptr<InputSpec> reference;
  double kp = 0, kd = 0;
  Feedforward feedforward = Feedforward::None;
  /// The PD law as a digital controller: sampled every sample_time [s] (0: continuous), its output
  /// held from `delay` samples later (solvers/inputs.hpp, sampled_law).
  double sample_time = 0;
  int delay = 0;
  bool none_given = false;  ///< a URDF joint the case gives no input: free, under zero torque
  bool prescribed() const { return is_motion(kind); }
};

/// The `[simulation]` table: the integrator's settings (their defaults are IntegratorOptions') and
/// what to run and store.
struct SimulationSettings {
  IntegratorOptions options;
  Procedure procedure = Procedure::Single;  ///< single, or paper (rigid inverse dynamics, kinematic, force input)
  int flexible_every = 0;            ///< store the full flexible state every k outputs (0: never)
  /// Start from a saved simulation state (simulation/state.hpp: save_state), resolved against the
  /// case's folder; "" for the case's own initial state.
  std::string state;
};

/// A flexible link of a case: [link] (the only one) or an element of [[links]].
struct LinkCase {
  std::string name;  ///< [link]: "link"; [[links]]: its name (default link1, link2, …)
  std::string key;   ///< where its keys are: "link" or "links.i" (messages)
  FlexibleLink link;
  int n = 0;         ///< its n if given (0: each segment's parts)
  int modes = 0;     ///< modal reduction: modes kept (0: every rfe coordinate; solvers/reduction.hpp)
  int modes_line = 0;  ///< where `modes` is written (messages; 0: not in the file)
  int derivatives = 0;  ///< static modal derivatives of the first `derivatives` modes (solvers/modes.hpp)
  int derivatives_line = 0;
  Mounting on;       ///< what it sits on (resolved; default: the last joint)
};

/// A frame fixed to a body, by name: a URDF link, welded to the body of the joint that moves it
/// (through a chain of fixed joints: X), or to the ground (joint −1).
struct BodyFrame {
  std::string name;
  int joint = -1;
  Mat4 X = Mat4::Identity();
};

struct Case {
  std::string path;      ///< the file (or the name given to parse_case): messages start with it
  std::string base_dir;  ///< where relative table and results paths are found ("" or ending in '/')
  std::string text;      ///< the file as read (stored with results)
  std::string effective_text;          ///< the case after the overrides, as TOML
  std::vector<std::string> overrides;  ///< the --set key.path=value strings applied
  std::vector<std::string> warnings;   ///< legal but suspicious values ("file:line: key: …")
  std::string name, description;
  std::vector<LinkCase> links;     ///< [link] or [[links]]
  bool has_link() const { return !links.empty(); }
  /// Index of the link named `name`, −1 if none.
  int link_index(const std::string& name) const {
    for (size_t l = 0; l < links.size(); ++l)
      if (links[l].name == name) return static_cast<int>(l);
    return -1;
  }
  std::vector<Joint> joints;       ///< a free base's six joints first, then [[joints]] (mountings resolved)
  bool free_base = false;          ///< [base] kind = "free"
  std::string urdf;                ///< [base] urdf: the file the first joints came from ("" if none)
  std::vector<BodyFrame> frames;   ///< the URDF's links (what a link or joint may be mounted on by name)
  std::vector<SensorSpec> sensors; ///< [[sensors]]: what a controller sees and a run records
  VecX joint_values, joint_rates;  ///< initial/held values and steady rates
  double gravity = 0.0;
  TipLoads loads;                  ///< on the link [loads] names (the last by default)
  std::vector<InputSpec> inputs;  ///< one per joint
  SimulationSettings sim;
  bool has_simulation = false;
  AccuracySpec accuracy;           ///< [accuracy]: a target instead of an n (none: not given)
};

/// Reads and validates a case file; `overrides` are "key.path=value" strings applied before
/// checking (array elements by index: "joints.0.value=0.5", "link.segments.1.parts=4"; a bare word
/// is a string). Throws CaseError.
Case read_case(const std::string& path, const std::vector<std::string>& overrides = {});
/// The same from TOML text: `name` stands for the file in messages, relative table paths are
/// resolved against `base_dir` (default: the current directory).
Case parse_case(const std::string& text, const std::string& name = "<text>",
                const std::vector<std::string>& overrides = {}, const std::string& base_dir = "");
/// The case with further overrides (after its own), read again from its text and checked as the
/// file is: a bad value is a CaseError naming the key.
Case with_overrides(const Case& c, const std::vector<std::string>& more);

/// Builds the model with n rfes in all (n > 0: distributed over every link's segments by length;
/// n == 0: each link's own discretisation). Throws CaseError for an impossible discretisation, for
/// n < 0 or n > kMaxRfes, and for n > 0 in a case without a flexible link.
Model build_model(const Case& c, int n = 0);
/// The number of parts of each link's segments for n rfes in all (as build_model distributes them).
std::vector<std::vector<int>> link_parts(const Case& c, int n);

}  // namespace rfem
