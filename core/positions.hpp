#pragma once
// Where the points of a model are at full coordinates q (flexible first, joints last): link tips,
// points along a link's elastic axis, joint frames; and the paper's tip deflections.
#include "model.hpp"

namespace rfem {

/// Link l's free end: displacement (3, in its {r}) and small rotation φ of rfe_n (3) relative to
/// undeformed. Zero for a rigid link.
Vec6 tip_motion(const Model& model, int l, const VecX& q);
/// The tip deflections in the paper's notation (docs/formulation.md §6): u1 along y of {r} (in the
/// plane of joints 2 and 3 for the paper's manipulator), u2 along z, θ the torsion φ1 of rfe_n.
Vec3 tip_deflection(const Model& model, int l, const VecX& q);
/// The point at s along link l's elastic axis in {r}, moving with the rfe whose span holds it
/// (rfe_0's span, or a rigid link: rigid with {r}).
Vec3 point_in_link_frame(const Model& model, int l, double s, const VecX& q);
/// The same point in the inertial frame {0}.
Vec3 point_position(const Model& model, int l, double s, const VecX& q);
/// Points at s[i] along link l's elastic axis in {0} (pos) and their displacement from the undeformed
/// axis, in {0} axes (deflection): one kinematics pass for all points. With `rotation`, also the
/// orientation of the body each point moves with ({r} on the span of rfe_0 and for a rigid link,
/// else its rfe's frame): the rotation from that frame to {0}.
void axis_points(const Model& model, int l, const std::vector<double>& s, const VecX& q, std::vector<Vec3>& pos,
                 std::vector<Vec3>& deflection, std::vector<Mat3>* rotation = nullptr);
/// The stations axis_points draws a link at: its start, every rfe's mass centre, its free end.
std::vector<double> axis_stations(const Model& model, int l);
/// How a point on a link's elastic axis moves (in {0}), and the body it moves with.
struct PointMotion {
  Vec3 position, velocity, acceleration;  ///< of the point, in {0} [m, m/s, m/s²]
  Mat3 rotation;                          ///< from the body's frame to {0}
  Vec3 angular_velocity;                  ///< of the body, in {0} [rad/s]
  Mat4 frame;                             ///< the link's frame {r}: its pose in {0}
};
/// The point at s along link l's elastic axis at full coordinates q, rates v and accelerations a
/// (each of model.dof()): with T the pose of the body it moves with (B0 for a rigid link or rfe_0's
/// span, B0 D_k with D_k the rfe's deformation transform [2.4] otherwise), p = T η,
/// ṗ = Ṫ η, p̈ = T̈ η and [ω×] = Ṙ Rᵀ (docs/formulation.md §3).
PointMotion point_motion(const Model& model, int l, double s, const VecX& q, const VecX& v, const VecX& a);
/// Position of link l's free end (on the elastic axis) in the inertial frame {0}.
Vec3 tip_position(const Model& model, int l, const VecX& q);
/// Origin of every joint's frame (where the body it moves is placed) in {0}.
std::vector<Vec3> joint_positions(const Model& model, const VecX& q);

}  // namespace rfem
