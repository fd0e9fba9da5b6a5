#pragma once
// The names a case file and a results file use for its choices, each written once: the kinds of
// joint input, the procedures and their runs, the feed-forward of a PD input.
#include <string>
#include <vector>

namespace rfem {

/// A joint's input kind (`joints[].input.kind`).
enum class InputKind { Deployment, Spinup, ConstantRate, Table, Torque, TorqueTable, TorqueFromRun, Pd };
std::string to_string(InputKind k);
/// False for an unknown name.
bool parse(const std::string& name, InputKind& k);
/// Every kind's name, comma-separated (for messages).
std::string input_kind_names();
/// A prescribed motion (kinematic input): deployment, spinup, constant_rate, table.
bool is_motion(InputKind k);

/// `simulation.procedure`: one run, or the paper's three (rigid, kinematic, force).
enum class Procedure { Single, Paper };
std::string to_string(Procedure p);
bool parse(const std::string& name, Procedure& p);

/// The runs of the procedures: `run` (single); `rigid`, `kinematic`, `force` (paper). Results
/// files name their groups so.
enum class RunName { Run, Rigid, Kinematic, Force };
std::string to_string(RunName r);
bool parse(const std::string& name, RunName& r);
/// The runs of a procedure, in the order they run.
std::vector<RunName> runs_of(Procedure p);

/// A PD input's feed-forward: none, or the rigid manipulator's inverse dynamics (computed torque).
enum class Feedforward { None, Rigid };
std::string to_string(Feedforward f);
bool parse(const std::string& name, Feedforward& f);

}  // namespace rfem
