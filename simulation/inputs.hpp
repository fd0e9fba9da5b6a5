#pragma once
// The joints' inputs of a case as laws (solvers/inputs.hpp): prescribed motions, torques, tables,
// the torques of an earlier run, PD feedback with the rigid manipulator's computed torque.
#include <memory>
#include <vector>

#include "../cases/case_file.hpp"
#include "../solvers/inputs.hpp"
#include "common.hpp"

namespace rfem {

/// One input per joint of the case. Reads tabulated files and earlier results (torque_from_run:
/// a cubic spline through that run's joint torques, which must reach this case's t_end); a source
/// run that did not complete is a warning. Throws CaseError naming the input ("FILE:LINE: joints.2.input…").
std::vector<JointInput> joint_inputs(const Case& cs, const Warnings& warn = {});

/// Force input reproducing the rigid manipulator's inverse dynamics of the given motion laws,
/// evaluated exactly at every time (the paper's step 2). The laws share `rigid`.
std::vector<JointInput> rigid_torque_inputs(std::shared_ptr<const Model> rigid, const std::vector<JointInput>& laws);

/// "motion", "torque" or "feedback": what each input is (results files record it).
std::vector<std::string> input_kinds(const std::vector<JointInput>& inputs);

}  // namespace rfem
