#pragma once
// Plain dense assembly straight from the paper's definitions, body by body and coordinate by
// coordinate (O(N²) work): a_ij = Σ_bodies tr(∂W/∂q_i H ∂W/∂q_jᵀ) [3.10]–[3.11], and the Hessians
// of the elastic [3.12] and gravity [3.18] energies. The reference the sparse assembly is tested
// against; not for production use.
#include "../core/model.hpp"

namespace rfem {

/// Includes the joint drives' inertia on the base diagonal.
MatX dense_mass_matrix(const Model& model, const VecX& q);
/// ∂²(V_e + V_g)/∂q² (gravity only if `gravity`).
MatX dense_stiffness(const Model& model, const VecX& q, bool gravity);
/// ∂²R/∂q̇² of the sde damping (Rayleigh dissipation function), plus the joint drives'
/// ∂τ_drive/∂q̇ at the velocities v (base diagonal).
MatX dense_damping(const Model& model, const VecX& q, const VecX& v);

}  // namespace rfem
