#pragma once
// The scalar quantities of a refinement study, typed: static tips, modal frequencies, and dynamic
// peaks or values at an output time of a run of the case's procedure (README, `rfem refine`).
//   [LINK/]tip:ux|uy|uz|rx|ry|rz           static tip of a link (default: the last)
//   mode:K, axial:K, bending-y:K, bending-z:K, torsion:K    K-th frequency (of that kind) [Hz]
//   [RUN/][LINK/]peak:u1|u2|theta          peak |tip deflection| over a run
//   [RUN/][LINK/]u1@T, u2@T, theta@T       tip deflection at output time T
//   [RUN/]tauJ@T, qJ@T                     torque or coordinate of joint J (from 1) at T
#include <string>
#include <vector>

#include "rfem/solvers/equations.hpp"
#include "rfem/studies/common.hpp"

namespace rfem {

struct Quantity {
  enum class Kind {
    Tip,         ///< static tip component `component` (0–5) of link `link`
    Mode,        ///< the K-th frequency
    ModeOfKind,  ///< the K-th frequency of kind `mode_kind`
    Peak,        ///< peak |value| over a run
    AtTime,      ///< the value at output time `time`
  };
  std::string text;       ///< as given
  Kind kind = Kind::Tip;
  int link = -1;          ///< tip quantities: the link (−1: the last)
  int component = 0;      ///< Tip: 0–5; Peak/AtTime on a tip: 0 u1, 1 u2, 2 θ
  int mode = 0;           ///< Mode, ModeOfKind: K ≥ 1
  std::string mode_kind;  ///< ModeOfKind: axial, bending-y, bending-z, torsion
  std::string run;        ///< dynamic: the run's name (run, rigid, kinematic, force)
  int joint = -1;         ///< dynamic joint quantities: the joint (1-based); −1: a tip quantity
  bool coordinate = false;///< joint quantity: q (else the torque τ)
  double time = -1.0;     ///< AtTime: [s]
  bool dynamic() const { return kind == Kind::Peak || kind == Kind::AtTime; }
};

/// Parses and checks a quantity against the case (a T off the output grid, an unknown run, link
/// or joint): CaseError with a one-line message.
Quantity parse_quantity(const Case& cs, const std::string& text);
/// A static or modal quantity at n rfes.
double evaluate_quantity(const Case& cs, int n, const Quantity& q, const JointRate& rate = {});
/// The same from its text.
double evaluate_quantity(const Case& cs, int n, const std::string& text, const JointRate& rate = {});
/// A dynamic quantity's value in one output sample of its run (peaks take the |value|'s maximum).
double sample_value(const Model& model, const Quantity& q, const OutputSample& s);

}  // namespace rfem
