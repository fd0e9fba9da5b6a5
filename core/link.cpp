#include "link.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "check.hpp"

namespace rfem {

void FlexibleLink::check() const {
  if (segments.empty()) throw std::invalid_argument("a flexible link needs at least one segment");
  for (size_t s = 0; s < segments.size(); ++s) {
    const Segment& seg = segments[s];
    const std::string who = "segment " + std::to_string(s + 1) + ": ";
    require_positive(who + "length", seg.length);
    if (seg.parts < 1) throw std::invalid_argument(who + "parts must be at least 1 (got " + std::to_string(seg.parts) + ")");
    seg.material.check();
    seg.section.check();
  }
  require_non_negative("damping_beta", damping_beta);
  const double L = total_length();
  for (size_t i = 0; i < payloads.size(); ++i) {
    const std::string who = "payload " + std::to_string(i + 1) + ": ";
    require_finite(who + "at", payloads[i].at);
    if (payloads[i].at < 0.0 || payloads[i].at > L * (1 + 1e-12))
      throw std::invalid_argument(who + "at = " + std::to_string(payloads[i].at) + " m is off the link (0 to " +
                                  std::to_string(L) + " m)");
    require_positive(who + "mass", payloads[i].H(3, 3));
    if (!payloads[i].H.allFinite()) throw std::invalid_argument(who + "inertia must be finite");
  }
}

double FlexibleLink::total_length() const {
  double L = 0.0;
  for (const auto& s : segments) L += s.length;
  return L;
}

Mat4 pseudo_inertia(double mass, const Vec3& c, const Mat3& I_c) {
  Mat4 H = Mat4::Zero();
  H.topLeftCorner<3, 3>() = 0.5 * I_c.trace() * Mat3::Identity() - I_c + mass * c * c.transpose();
  H.topRightCorner<3, 1>() = mass * c;
  H.bottomLeftCorner<1, 3>() = mass * c.transpose();
  H(3, 3) = mass;
  return H;
}

namespace {

// Mass and second moments of the piece [a, b] of one segment, accumulated about the origin of {r}:
// G = ∫[x;1][x;1]ᵀ dm in {r}.
Mat4 piece_moments(const Segment& s, double a, double b) {
  const double l = b - a;
  const double m = s.material.rho * s.section.A * l;
  const Vec3 c(0.5 * (a + b), s.section.offset.y(), s.section.offset.z());
  Mat3 J = Mat3::Zero();  // ∫ r'r'ᵀ dm about the piece's centre
  J(0, 0) = m * l * l / 12.0;
  J(1, 1) = s.material.rho * s.section.Iz * l;
  J(2, 2) = s.material.rho * s.section.Iy * l;
  Mat4 G = Mat4::Zero();
  G.topLeftCorner<3, 3>() = J + m * c * c.transpose();
  G.topRightCorner<3, 1>() = m * c;
  G.bottomLeftCorner<1, 3>() = m * c.transpose();
  G(3, 3) = m;
  return G;
}

// The rfe spanning [a, b]: combine the pieces of every segment it overlaps about their common
// mass centre.
Rfe make_rfe(const FlexibleLink& link, const std::vector<double>& seg_start, double a, double b) {
  Mat4 G = Mat4::Zero();
  for (size_t s = 0; s < link.segments.size(); ++s) {
    const double lo = std::max(a, seg_start[s]);
    const double hi = std::min(b, seg_start[s] + link.segments[s].length);
    if (hi - lo > 1e-14 * link.total_length()) G += piece_moments(link.segments[s], lo, hi);
  }
  const double L = link.total_length();
  for (const Payload& p : link.payloads)  // spans are [a, b), the last one [a, L]
    if (p.at >= a && (p.at < b || (b >= L && p.at <= L))) {
      Mat4 T = Mat4::Identity();  // moments about {r}'s origin: T H Tᵀ with T = Trans(at, 0, 0)
      T(0, 3) = p.at;
      G += T * p.H * T.transpose();
    }
  Rfe r;
  r.mass = G(3, 3);
  r.centre = G.topRightCorner<3, 1>() / r.mass;
  Mat4 shift = Mat4::Identity();  // moments about the mass centre: T G Tᵀ with T = Trans(−c)
  shift.topRightCorner<3, 1>() = -r.centre;
  r.H = shift * G * shift.transpose();
  r.H.topRightCorner<3, 1>().setZero();  // exact zeros instead of round-off
  r.H.bottomLeftCorner<1, 3>().setZero();
  r.start = a;
  r.end = b;
  return r;
}

}  // namespace

std::vector<int> distribute_parts(const FlexibleLink& link, int n) {
  const int ns = static_cast<int>(link.segments.size());
  if (n < ns)
    throw std::invalid_argument("n = " + std::to_string(n) + " rfes cannot cover " + std::to_string(ns) +
                                " segments (need at least one part per segment)");
  const double L = link.total_length();
  std::vector<int> parts(ns, 1);
  int given = ns;
  // Largest-remainder apportionment of the remaining parts by length.
  std::vector<double> want(ns);
  for (int s = 0; s < ns; ++s) want[s] = n * link.segments[s].length / L - 1.0;
  while (given < n) {
    int best = 0;
    for (int s = 1; s < ns; ++s)
      if (want[s] - parts[s] > want[best] - parts[best]) best = s;
    ++parts[best];
    ++given;
  }
  return parts;
}

int rfe_at(const Discretisation& d, double s) {
  const int n = d.n();
  if (n == 0 || s < d.rfes[0].start) return -1;
  // Spans are contiguous and sorted: the last rfe starting at or before s.
  const auto it = std::upper_bound(d.rfes.begin(), d.rfes.end(), s, [](double x, const Rfe& r) { return x < r.start; });
  return static_cast<int>(it - d.rfes.begin()) - 1;
}

Discretisation Discretisation::rigid() const {
  Discretisation r;
  r.length = length;
  r.damping_beta = damping_beta;
  r.payloads = payloads;
  auto moments = [](const Rfe& e) {  // ∫[x;1][x;1]ᵀ dm about {r}'s origin
    const Mat4 X = homogeneous(Mat3::Identity(), e.centre);
    return Mat4(X * e.H * X.transpose());
  };
  r.rfe0.H = moments(rfe0);
  for (const Rfe& e : rfes) r.rfe0.H += moments(e);
  r.rfe0.mass = r.rfe0.H(3, 3);
  r.rfe0.end = length;
  r.tip_eta = Vec3(length, 0.0, 0.0);
  return r;
}

Discretisation discretise(const FlexibleLink& link) {
  link.check();
  Discretisation d;
  d.length = link.total_length();
  d.damping_beta = link.damping_beta;
  d.payloads = link.payloads;
  std::vector<double> seg_start;
  double x = 0.0;
  for (const auto& s : link.segments) {
    seg_start.push_back(x);
    x += s.length;
  }
  // Primary division: sdes at part midpoints. Reserved exactly: at 10⁴ rfes a doubling vector's
  // spare capacity is up to 0.3 kB per rfe of a run's memory.
  int parts = 0;
  for (const auto& s : link.segments) parts += s.parts;
  d.sdes.reserve(parts);
  d.rfes.reserve(parts);
  for (size_t s = 0; s < link.segments.size(); ++s) {
    const Segment& seg = link.segments[s];
    const double dl = seg.length / seg.parts;
    const double EA = seg.material.E * seg.section.A, GA = seg.material.G * seg.section.A;
    for (int p = 0; p < seg.parts; ++p) {
      Sde e;
      e.position = seg_start[s] + (p + 0.5) * dl;
      e.segment = static_cast<int>(s);
      e.c = Vec3(EA, seg.section.kappa_y * GA, seg.section.kappa_z * GA) / dl;
      e.k = Vec3(seg.material.G * seg.section.J, seg.material.E * seg.section.Iy,
                 seg.material.E * seg.section.Iz) / dl;
      d.sdes.push_back(e);
    }
  }
  // Secondary division: rfes between consecutive sdes; the clamped half-part is rfe_0.
  const int n = static_cast<int>(d.sdes.size());
  d.rfe0 = make_rfe(link, seg_start, 0.0, d.sdes[0].position);
  for (int k = 0; k < n; ++k) {
    const double a = d.sdes[k].position, b = (k + 1 < n) ? d.sdes[k + 1].position : d.length;
    d.rfes.push_back(make_rfe(link, seg_start, a, b));
  }
  for (int e = 0; e < n; ++e) {
    Sde& s = d.sdes[e];
    s.left = e - 1;
    s.right = e;
    const Vec3 point(s.position, 0.0, 0.0);  // on the elastic axis
    s.eta_left = point - (e == 0 ? d.rfe0.centre : d.rfes[e - 1].centre);
    s.eta_right = point - d.rfes[e].centre;
  }
  d.tip_eta = Vec3(d.length, 0.0, 0.0) - d.rfes.back().centre;
  // What the given values derive must be usable numbers too (1e308 kg/m³ times a volume is not).
  for (int k = 0; k <= n; ++k) {
    const Rfe& r = k == 0 ? d.rfe0 : d.rfes[k - 1];
    if (!r.H.allFinite() || !std::isfinite(r.mass) || !(r.mass > 0.0) || !r.centre.allFinite())
      throw std::invalid_argument("rfe " + std::to_string(k) + ": its mass or inertia is not a positive finite number "
                                  "(the segments' values overflow or vanish)");
  }
  for (int e = 0; e < n; ++e)
    if (!d.sdes[e].c.allFinite() || !d.sdes[e].k.allFinite() || !(d.sdes[e].c.minCoeff() > 0.0) || !(d.sdes[e].k.minCoeff() > 0.0))
      throw std::invalid_argument("sde " + std::to_string(e + 1) + ": its stiffness is not a positive finite number "
                                  "(the segments' values overflow or vanish)");
  return d;
}

}  // namespace rfem
