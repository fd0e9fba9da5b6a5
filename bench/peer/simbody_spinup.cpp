// Independent peer check of rfem with Simbody: Kane's spin-up beam (cases/kane_spinup.toml) built as
// the same RFEM chain of rigid bodies and springs, integrated by Simbody's own equations of motion.
//
// This program must not link rfem's libraries: libSimTKmath exports old SUNDIALS N_V* symbols that
// would silently replace SUNDIALS 6's in one process. So the beam data
// of the case are repeated here, and the comparison with rfem's HDF5 output is done by compare.py.
//
// Model (rfem's discretisation, core/link.cpp): n equal parts of length Δl = L/n, one sde at the
// middle of each part; rfes lie between consecutive sdes; the clamped half-part (rfe_0) is rigid
// with the hub, the free-end half-part is the last rfe. Bodies:
//   hub   Pin about ground z, angle prescribed by Kane's spin-up law (a Motion, so exact in time);
//         carries rfe_0's inertia (irrelevant under prescribed motion, but physically right).
//   rfe k Free mobilizer relative to its inboard neighbour (rfe k-1, or the hub), with both
//         mobilizer frames at the sde between them, so q = 0 is the undeformed beam. Simbody's
//         coordinates are thus relative (joint) coordinates, unlike rfem's base-frame ones.
// Springs (--sde):
//   bushing  Force::LinearBushing at each sde, stiffness [GJ EIy EIz EA κGA κGA]/Δl in the frame
//            of the inboard rfe, rotations as x-y-z body-fixed Euler angles of the relative rotation:
//            an element written independently of rfem, equal to rfem's sde to first order.
//   rfem     rfem's sde energy exactly (docs/formulation.md §3): Δx = p_p − p_l in hub axes and
//            Δφ = φ_p − φ_l with φ the X-Y-Z angles of each rfe relative to the hub. Then the only
//            remaining difference to rfem is the equations of motion and the integrator.

#include <Simbody.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

using namespace SimTK;

namespace {

// cases/kane_spinup.toml (and kappa = 5/6, rfem's default).
struct Beam {
  double L = 10.0, E = 7.0e10, G = 2.6923076923e10, rho = 3000.0;
  double A = 4.0e-4, Iy = 2.0e-7, Iz = 2.0e-7, J = 4.0e-7, kappa = 5.0 / 6.0;
};

// Kane's spin-up law θ(t) = (Ω/T)(t²/2 + (T/2π)²(cos(2πt/T) − 1)) for t ≤ T, then Ω(t − T/2).
struct SpinUp {
  double Omega = 6.0, T = 15.0;
  void eval(double t, double& q, double& qd, double& qdd) const {
    if (t <= T) {
      const double w = 2.0 * Pi / T, c = std::cos(w * t), s = std::sin(w * t);
      q = (Omega / T) * (0.5 * t * t + (c - 1.0) / (w * w));
      qd = (Omega / T) * (t - s / w);
      qdd = (Omega / T) * (1.0 - c);
    } else {
      q = Omega * (t - 0.5 * T);
      qd = Omega;
      qdd = 0.0;
    }
  }
};

// Position-level prescribed motion: Simbody then treats the hub angle as a known function of time
// (no constraint, no projection), exactly like rfem's kinematic input.
class SpinUpMotion : public Motion::Custom::Implementation {
 public:
  explicit SpinUpMotion(SpinUp law) : law_(law) {}
  Implementation* clone() const override { return new SpinUpMotion(*this); }
  Motion::Level getLevel(const State&) const override { return Motion::Position; }
  void calcPrescribedPosition(const State& s, int /*nq = 1*/, Real* q) const override {
    double v, a;
    law_.eval(s.getTime(), q[0], v, a);
  }
  void calcPrescribedPositionDot(const State& s, int /*nq = 1*/, Real* qd) const override {
    double q, a;
    law_.eval(s.getTime(), q, qd[0], a);
  }
  void calcPrescribedPositionDotDot(const State& s, int /*nq = 1*/, Real* qdd) const override {
    double q, v;
    law_.eval(s.getTime(), q, v, qdd[0]);
  }

 private:
  SpinUp law_;
};

// One sde between bodies l (inboard) and p (outboard): attachment stations on each body, translational
// stiffness c and rotational stiffness k, in rfem's order (axial/torsion first).
struct Sde {
  int l, p;  // body indices into the list {hub, rfe_1, …, rfe_n}
  Vec3 eta_l, eta_p;
  Vec3 c, k;
};

// rfem's sde energy, transcribed from docs/formulation.md §3 (not from rfem's code): with the hub frame {r},
//   V = Σ_e ½ Δxᵀ diag(c) Δx + ½ Δφᵀ diag(k) Δφ,  Δx = p_p − p_l in {r} axes,  Δφ = φ_p − φ_l,
// φ_k = X-Y-Z body-fixed angles of rfe k's rotation in {r} (0 for the hub). The translational part is
// applied as forces at the attachment stations (exact virtual work); the angular part as generalised
// forces Q = −∂V/∂φ, mapped to a body torque τ_B = N_Bᵀ Q (φ̇ = N_B ω_B), reacted on the hub.
class RfemSdeForce : public Force::Custom::Implementation {
 public:
  RfemSdeForce(std::vector<MobilizedBody> bodies, std::vector<Sde> sdes)
      : bodies_(std::move(bodies)), sdes_(std::move(sdes)) {}

  void calcForce(const State& s, Vector_<SpatialVec>& bodyForces, Vector_<Vec3>&,
                 Vector&) const override {
    const MobilizedBody& hub = bodies_[0];
    const Rotation& R_GH = hub.getBodyRotation(s);
    const std::vector<Vec3> phi = angles(s);
    std::vector<Vec3> Q(bodies_.size(), Vec3(0));
    for (const Sde& e : sdes_) {
      const MobilizedBody &bl = bodies_[e.l], &bp = bodies_[e.p];
      const Vec3 pl_G = bl.findStationLocationInGround(s, e.eta_l);
      const Vec3 pp_G = bp.findStationLocationInGround(s, e.eta_p);
      const Vec3 dx = ~R_GH * (pp_G - pl_G);
      const Vec3 f_G = R_GH * e.c.elementwiseMultiply(dx);
      bp.applyForceToBodyPoint(s, e.eta_p, -f_G, bodyForces);
      bl.applyForceToBodyPoint(s, e.eta_l, f_G, bodyForces);
      const Vec3 m = e.k.elementwiseMultiply(phi[e.p] - phi[e.l]);
      Q[e.p] -= m;
      Q[e.l] += m;
    }
    for (size_t b = 1; b < bodies_.size(); ++b) {
      const Vec3 tau_B = ~Rotation::calcNForBodyXYZInBodyFrame(phi[b]) * Q[b];
      const Vec3 tau_G = bodies_[b].getBodyRotation(s) * tau_B;
      bodies_[b].applyBodyTorque(s, tau_G, bodyForces);
      hub.applyBodyTorque(s, -tau_G, bodyForces);
    }
  }

  Real calcPotentialEnergy(const State& s) const override {
    const Rotation& R_GH = bodies_[0].getBodyRotation(s);
    const std::vector<Vec3> phi = angles(s);
    Real V = 0;
    for (const Sde& e : sdes_) {
      const Vec3 dx = ~R_GH * (bodies_[e.p].findStationLocationInGround(s, e.eta_p) -
                               bodies_[e.l].findStationLocationInGround(s, e.eta_l));
      const Vec3 dphi = phi[e.p] - phi[e.l];
      V += 0.5 * (~dx * e.c.elementwiseMultiply(dx) + ~dphi * e.k.elementwiseMultiply(dphi));
    }
    return V;
  }

 private:
  std::vector<Vec3> angles(const State& s) const {
    const Rotation& R_GH = bodies_[0].getBodyRotation(s);
    std::vector<Vec3> phi(bodies_.size(), Vec3(0));
    for (size_t b = 1; b < bodies_.size(); ++b)
      phi[b] = (~R_GH * bodies_[b].getBodyRotation(s)).convertRotationToBodyFixedXYZ();
    return phi;
  }

  std::vector<MobilizedBody> bodies_;
  std::vector<Sde> sdes_;
};

// Mass properties of the beam piece of length ell, about its mass centre, principal axes = link axes:
// about x ∫(y²+z²)dm = ρℓ(Iy+Iz); about y ∫(x²+z²)dm = mℓ²/12 + ρℓIy; about z mℓ²/12 + ρℓIz.
MassProperties piece(const Beam& b, double ell) {
  const double m = b.rho * b.A * ell;
  return MassProperties(m, Vec3(0),
                        Inertia(b.rho * ell * (b.Iy + b.Iz), m * ell * ell / 12 + b.rho * ell * b.Iy,
                                m * ell * ell / 12 + b.rho * ell * b.Iz));
}

struct Options {
  int n = 10;
  std::string out = "simbody_spinup.csv";
  std::string integrator = "rkm";  // rkm | rkf | rk3 | cpodes
  std::string sde = "bushing";     // bushing | rfem
  double accuracy = 1e-7;
  // Euler angles rather than quaternions on the Free mobilizers: no normalisation projection and
  // ~20 % fewer RKM steps here; their singularity (middle angle at 90°) is far from these small
  // relative rotations.
  bool euler = true;
  int max_order = 0;               // cpodes only: BDF order limit (0: CPodes' default, 5)
  double t_end = 20.0, dt = 0.05;
};

[[noreturn]] void usage(const char* msg) {
  std::fprintf(stderr,
               "simbody_spinup: %s\n"
               "usage: simbody_spinup [--n N] [--out FILE.csv] [--integrator rkm|rkf|rk3|cpodes]\n"
               "                      [--accuracy A] [--max-order K (cpodes)] [--sde bushing|rfem]\n"
               "                      [--rotations quaternion|euler]\n"
               "                      [--t-end T] [--dt DT]\n",
               msg);
  std::exit(2);
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") usage("Kane's spin-up beam as an RFEM chain in Simbody");
    if (i + 1 >= argc) usage(("missing value after " + a).c_str());
    const std::string v = argv[++i];
    try {
      if (a == "--n") o.n = std::stoi(v);
      else if (a == "--out") o.out = v;
      else if (a == "--integrator") o.integrator = v;
      else if (a == "--sde") o.sde = v;
      else if (a == "--accuracy") o.accuracy = std::stod(v);
      else if (a == "--max-order") o.max_order = std::stoi(v);
      else if (a == "--rotations") {
        if (v != "quaternion" && v != "euler") usage("--rotations must be quaternion or euler");
        o.euler = (v == "euler");
      }
      else if (a == "--t-end") o.t_end = std::stod(v);
      else if (a == "--dt") o.dt = std::stod(v);
      else usage(("unknown option " + a).c_str());
    } catch (const std::logic_error&) {
      usage(("bad value for " + a + ": " + v).c_str());
    }
  }
  if (o.n < 1) usage("--n must be >= 1");
  if (!(o.accuracy > 0) || !(o.t_end > 0) || !(o.dt > 0)) usage("--accuracy, --t-end, --dt must be > 0");
  if (o.sde != "bushing" && o.sde != "rfem") usage("--sde must be bushing or rfem");
  if (o.integrator != "rkm" && o.integrator != "rkf" && o.integrator != "rk3" && o.integrator != "cpodes")
    usage("--integrator must be rkm, rkf, rk3 or cpodes");
  return o;
}

std::unique_ptr<Integrator> make_integrator(const Options& o, const System& sys) {
  if (o.integrator == "rkm") return std::make_unique<RungeKuttaMersonIntegrator>(sys);
  if (o.integrator == "rkf") return std::make_unique<RungeKuttaFeldbergIntegrator>(sys);
  if (o.integrator == "rk3") return std::make_unique<RungeKutta3Integrator>(sys);
  auto cp = std::make_unique<CPodesIntegrator>(sys, CPodes::BDF, CPodes::Newton);
  // BDF above order 2 is not A-stable, and the undamped axial/shear modes then cap the step (rfem
  // limits IDA to order 2 for the same reason). Even so, CPodes was not competitive here (README).
  if (o.max_order > 0) cp->setOrderLimit(o.max_order);
  return cp;
}

const char* integrator_title(const std::string& name) {
  if (name == "rkm") return "RungeKuttaMerson (explicit, 4th order, error-controlled)";
  if (name == "rkf") return "RungeKuttaFeldberg (explicit, 4/5th order, error-controlled)";
  if (name == "rk3") return "RungeKutta3 (explicit, 3rd order, error-controlled)";
  return "CPodes BDF + Newton (implicit, variable order, dense finite-difference Jacobian)";
}

}  // namespace

int main(int argc, char** argv) {
  const Options opt = parse(argc, argv);
  const Beam b;
  const int n = opt.n;
  const double dl = b.L / n;

  MultibodySystem system;
  SimbodyMatterSubsystem matter(system);
  GeneralForceSubsystem forces(system);  // no gravity: Kane's beam turns in a horizontal plane

  // Geometry along the link axis x of the hub frame {r}: sde e at (e + ½)Δl, rfe k spans
  // [s_k, s_{k+1}] (the last one [s_n, L]), rfe_0 = [0, Δl/2] is rigid with the hub.
  std::vector<double> s(n), centre(n + 1), length(n + 1);
  for (int e = 0; e < n; ++e) s[e] = (e + 0.5) * dl;
  length[0] = 0.5 * dl;
  centre[0] = 0.25 * dl;
  for (int k = 1; k <= n; ++k) {
    const double a = s[k - 1], z = (k < n) ? s[k] : b.L;
    length[k] = z - a;
    centre[k] = 0.5 * (a + z);
  }

  // The hub's origin is on the rotation axis; give it rfe_0's inertia shifted to that origin.
  const MassProperties mp0 = piece(b, length[0]);
  Body::Rigid hubBody(MassProperties(mp0.getMass(), Vec3(centre[0], 0, 0),
                                     mp0.getUnitInertia().shiftFromCentroid(Vec3(-centre[0], 0, 0))));
  MobilizedBody::Pin hub(matter.Ground(), Transform(), hubBody, Transform());
  SpinUp law;
  Motion::Custom spin(hub, new SpinUpMotion(law));

  std::vector<MobilizedBody> bodies{hub};
  std::vector<Sde> sdes;
  const Vec3 c = Vec3(b.E * b.A, b.kappa * b.G * b.A, b.kappa * b.G * b.A) / dl;
  const Vec3 k = Vec3(b.G * b.J, b.E * b.Iy, b.E * b.Iz) / dl;
  for (int e = 0; e < n; ++e) {
    // Bodies' origins are their mass centres (the hub's is on the axis).
    const Vec3 eta_l(s[e] - (e == 0 ? 0.0 : centre[e]), 0, 0);
    const Vec3 eta_p(s[e] - centre[e + 1], 0, 0);
    MobilizedBody::Free rfe(bodies.back(), Transform(eta_l), Body::Rigid(piece(b, length[e + 1])),
                            Transform(eta_p));
    if (opt.sde == "bushing")
      Force::LinearBushing(forces, bodies.back(), Transform(eta_l), rfe, Transform(eta_p),
                           Vec6(k[0], k[1], k[2], c[0], c[1], c[2]), Vec6(0));
    sdes.push_back({e, e + 1, eta_l, eta_p, c, k});
    bodies.push_back(rfe);
  }
  if (opt.sde == "rfem") Force::Custom(forces, new RfemSdeForce(bodies, sdes));

  const MobilizedBody& last = bodies.back();
  const Vec3 tip_station(b.L - centre[n], 0, 0);

  State state = system.realizeTopology();  // default state: q = 0 (undeformed), u = 0 (at rest)
  matter.setUseEulerAngles(state, opt.euler);
  system.realizeModel(state);
  system.realize(state, Stage::Position);

  std::unique_ptr<Integrator> integ = make_integrator(opt, system);
  integ->setAccuracy(opt.accuracy);
  // Finish a step exactly at each output time instead of interpolating: the steps are far shorter
  // than the output interval anyway (stiff axial/shear springs), so this costs almost nothing.
  integ->setAllowInterpolation(false);
  integ->setInternalStepLimit(0);
  integ->initialize(state);

  std::ofstream out(opt.out);
  if (!out) usage(("cannot write " + opt.out).c_str());
  out << "# simbody_spinup n=" << n << " sde=" << opt.sde << " integrator=" << opt.integrator
      << " accuracy=" << opt.accuracy << " rotations=" << (opt.euler ? "euler" : "quaternion") << "\n";
  out << "t,u1,u2\n";
  out.precision(12);

  double peak = 0, u1_at15 = NAN, u1_at20 = NAN;
  const int nout = static_cast<int>(std::lround(opt.t_end / opt.dt));
  // CPU time beside wall time: the team's machines are shared, and a busy neighbour stretches wall
  // time but not this single-threaded process's CPU time.
  const auto t0 = std::chrono::steady_clock::now();
  const std::clock_t c0 = std::clock();
  for (int i = 0; i <= nout; ++i) {
    const double t = i * opt.dt;
    if (i > 0) {
      try {
        // stepTo() also returns at the start of a continuous interval (first call) and at step
        // limits; only a return at t itself is an output.
        while (integ->getTime() < t - 1e-12 && !integ->isSimulationOver()) integ->stepTo(t);
      } catch (const std::exception& ex) {
        std::fprintf(stderr, "simbody_spinup: integration failed at t = %g: %s\n", integ->getTime(),
                     ex.what());
        return 1;
      }
      if (integ->getTime() < t - 1e-12) {
        std::fprintf(stderr, "simbody_spinup: integration stopped at t = %g\n", integ->getTime());
        return 1;
      }
    }
    const State& st = integ->getState();
    system.realize(st, Stage::Position);
    // Tip on the beam axis, displacement in the rotating hub frame.
    const Vec3 tip_G = last.findStationLocationInGround(st, tip_station);
    const Vec3 tip_H = (~hub.getBodyTransform(st)) * tip_G - Vec3(b.L, 0, 0);
    out << st.getTime() << ',' << tip_H[1] << ',' << tip_H[2] << '\n';
    peak = std::max(peak, std::abs(tip_H[1]));
    if (std::abs(t - 15.0) < 1e-9) u1_at15 = tip_H[1];
    if (std::abs(t - 20.0) < 1e-9) u1_at20 = tip_H[1];
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double cpu = double(std::clock() - c0) / CLOCKS_PER_SEC;
  // Trailer for compare.py (a comment line, so CSV readers skip it).
  out << "# wall_time_s=" << wall << " cpu_time_s=" << cpu << " steps=" << integ->getNumStepsTaken()
      << " realizations=" << integ->getNumRealizations() << "\n";

  std::printf("n               %d\n", n);
  std::printf("sde             %s (Free mobilizers on %s)\n", opt.sde.c_str(),
              opt.euler ? "Euler angles" : "quaternions");
  std::printf("integrator      %s, accuracy %g", integrator_title(opt.integrator), opt.accuracy);
  if (opt.integrator == "cpodes" && opt.max_order > 0) std::printf(", max order %d", opt.max_order);
  std::printf("\n");
  std::printf("wall time [s]   %.3f (CPU %.3f)\n", wall, cpu);
  std::printf("steps           %d (attempted %d, error-test failures %d, realizations %d)\n",
              integ->getNumStepsTaken(), integ->getNumStepsAttempted(), integ->getNumErrorTestFailures(),
              integ->getNumRealizations());
  std::printf("peak |u1| [m]   %.9f\n", peak);
  std::printf("u1(15 s) [m]    %.9f\n", u1_at15);
  std::printf("u1(20 s) [m]    %.9f\n", u1_at20);
  return 0;
}
