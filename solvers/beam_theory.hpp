#pragma once
// Exact results for a uniform cantilever (Euler–Bernoulli bending, rods in tension and torsion,
// Timoshenko shear deflection), the references rfem's discretisation converges to.
#include "../core/link.hpp"
#include "modes.hpp"

namespace rfem::beam {

/// k-th root (k ≥ 1) of 1 + cos x cosh x = 0: 1.875104, 4.694091, 7.854757, …
double cantilever_beta_l(int k);
/// k-th elastic root (k ≥ 1) of tan x = tanh x: βL of a pinned–free beam (and of clamped–pinned),
/// 3.926602, 7.068583, 10.210176, …
double pinned_free_beta_l(int k);
/// k-th elastic root (k ≥ 1) of cos x cosh x = 1: βL of a free–free beam (and of clamped–clamped),
/// 4.730041, 7.853205, 10.995608, …
double free_free_beta_l(int k);
/// k-th root λ = βL of the Euler–Bernoulli cantilever carrying at its free end a mass μ·ρAL with
/// rotary inertia η·ρAL³ about the tip:
///   1 + cos λ cosh λ + λμ(cos λ sinh λ − sin λ cosh λ) − λ³η(sin λ cosh λ + cos λ sinh λ)
///     + λ⁴μη(1 − cos λ cosh λ) = 0
/// (μ = η = 0: the free end; μ → ∞: pinned, tan λ = tanh λ; η → ∞: guided, tan λ = −tanh λ).
double cantilever_tip_mass_beta_l(double mu, double eta, int k);
/// k-th natural circular frequency [rad/s] of a uniform cantilever of the given kind.
double cantilever_omega(const Segment& s, ModeKind kind, int k);
/// k-th bending frequency [rad/s] of a uniform Timoshenko cantilever (shear deformation and rotary
/// inertia: what the RFEM discretisation converges to), from the clamped–free frequency equation
///   2 + [b²(r²−s²)² + 2] cosh(bα) cos(bβ) − b(r²+s²)/√(1 − b²r²s²) sinh(bα) sin(bβ) = 0,
/// b² = ρAL⁴ω²/(EI), r² = I/(AL²), s² = EI/(κGAL²), α, β = √(∓(r²+s²) + √((r²−s²)² + 4/b²))/√2
/// (Han, Benaroya & Wei, J. Sound Vib. 225(5), 1999). `kind`: BendingY or BendingZ.
double cantilever_omega_timoshenko(const Segment& s, ModeKind kind, int k);
/// Static tip deflection under a transverse tip force P along y (bending about z) or z:
/// P L³/(3 E I) + P L/(κ G A).
double cantilever_tip_deflection(const Segment& s, double P, bool along_z);
/// Tip rotation P L²/(2 E I).
double cantilever_tip_rotation(const Segment& s, double P, bool along_z);

}  // namespace rfem::beam
