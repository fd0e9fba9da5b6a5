#pragma once
// M_uu a = b for the unknowns (rfe coordinates and free joints) by block elimination: M over the
// chains' rfes is block-diagonal (each such rfe's W depends on its own coordinates only,
// docs/formulation.md §4), so with the border b (carrying rfes, free joints)
// a_b = (M_bb − Σ B_kᵀ M_kk⁻¹ B_k)⁻¹ (b_b − Σ B_kᵀ M_kk⁻¹ b_k) and a_k = M_kk⁻¹ (b_k − B_k a_b),
// with 6×6 solves per rfe and one nb×nb solve: O(n) work, no sparse factor to keep.
#include "../assembly/assemble.hpp"

namespace rfem {

/// Returns false if a block is not positive definite. `values` is scratch (pattern.nnz()); `ws`:
/// the caller's workspace (its thread count), or null for a local one.
bool solve_mass(const Model& model, const BorderedPattern& pattern, const std::vector<int>& base_col,
                const VecX& q, const VecX& v, VecX& b, std::vector<double>& values, Workspace* ws = nullptr);

}  // namespace rfem
