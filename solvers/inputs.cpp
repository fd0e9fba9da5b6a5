#include "inputs.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdlib>
#include <cmath>
#include <deque>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "../core/check.hpp"

namespace rfem {

namespace {

// Tables of more rows than this force no step ends at their nodes.
constexpr size_t kMaxTableBreakpoints = 1000;

// A table's columns: of equal length, finite.
void check_table(const std::vector<double>& t, const std::vector<double>& v) {
  if (t.size() != v.size())
    throw std::invalid_argument("a table needs as many values as times (" + std::to_string(t.size()) + " times, " +
                                std::to_string(v.size()) + " values)");
  for (size_t i = 0; i < t.size(); ++i)
    if (!std::isfinite(t[i]) || !std::isfinite(v[i]))
      throw std::invalid_argument("table row " + std::to_string(i + 1) + " is not finite");
}

class Deployment : public MotionLaw {
 public:
  Deployment(double psi0, double alpha, double T) : psi0_(psi0), k_(M_PI * alpha / (2 * T)), T_(T) {
    require_finite("deployment: the initial value", psi0);
    require_finite("deployment: alpha", alpha);
    require_positive("deployment: T", T);
    require_finite("deployment: its rate pi alpha / 2T", k_);
  }
  MotionSample at(double t) const override {
    if (t >= T_) return {psi0_ - k_ * T_, 0.0, 0.0};
    const double w = 2 * M_PI / T_;
    return {psi0_ - k_ * (t - std::sin(w * t) / w), -k_ * (1 - std::cos(w * t)), -k_ * w * std::sin(w * t)};
  }
  std::vector<double> breakpoints() const override { return {T_}; }  // the jerk jumps at the end

 private:
  double psi0_, k_, T_;
};

class Spinup : public MotionLaw {
 public:
  Spinup(double th0, double Omega, double T) : th0_(th0), W_(Omega), T_(T) {
    require_finite("spinup: the initial value", th0);
    require_finite("spinup: Omega", Omega);
    require_positive("spinup: T", T);
    require_finite("spinup: its acceleration Omega / T", Omega / T);
  }
  MotionSample at(double t) const override {
    if (t >= T_) return {th0_ + W_ * (t - T_ / 2), W_, 0.0};
    const double w = 2 * M_PI / T_;
    return {th0_ + (W_ / T_) * (t * t / 2 + (std::cos(w * t) - 1) / (w * w)), (W_ / T_) * (t - std::sin(w * t) / w),
            (W_ / T_) * (1 - std::cos(w * t))};
  }
  std::vector<double> breakpoints() const override { return {T_}; }

 private:
  double th0_, W_, T_;
};

class ConstantRate : public MotionLaw {
 public:
  ConstantRate(double q0, double rate) : q0_(q0), rate_(rate) {
    require_finite("constant_rate: the initial value", q0);
    require_finite("constant_rate: rate", rate);
  }
  MotionSample at(double t) const override { return {q0_ + rate_ * t, rate_, 0.0}; }

 private:
  double q0_, rate_;
};

class Spline : public MotionLaw {
 public:
  Spline(std::vector<double> t, std::vector<double> q) : t_(std::move(t)), q_(std::move(q)), m_(t_.size(), 0.0) {
    const size_t n = t_.size();
    check_table(t_, q_);
    if (n < 3) throw std::invalid_argument("a tabulated motion needs at least 3 points");
    for (size_t i = 1; i < n; ++i)
      if (!(t_[i] > t_[i - 1])) throw std::invalid_argument("tabulated times must increase");
    // Natural spline second derivatives m_i: tridiagonal system (Thomas algorithm).
    std::vector<double> a(n, 0), b(n, 1), c(n, 0), d(n, 0);
    for (size_t i = 1; i + 1 < n; ++i) {
      const double h0 = t_[i] - t_[i - 1], h1 = t_[i + 1] - t_[i];
      a[i] = h0;
      b[i] = 2 * (h0 + h1);
      c[i] = h1;
      d[i] = 6 * ((q_[i + 1] - q_[i]) / h1 - (q_[i] - q_[i - 1]) / h0);
    }
    for (size_t i = 1; i < n; ++i) {
      const double w = a[i] / b[i - 1];
      b[i] -= w * c[i - 1];
      d[i] -= w * d[i - 1];
    }
    m_[n - 1] = d[n - 1] / b[n - 1];
    for (size_t i = n - 1; i-- > 0;) m_[i] = (d[i] - c[i] * m_[i + 1]) / b[i];
  }
  MotionSample at(double t) const override {
    if (t < t_.front() - 1e-12 || t > t_.back() + 1e-12)
      throw std::runtime_error("time " + std::to_string(t) + " s is outside the tabulated motion [" +
                               std::to_string(t_.front()) + ", " + std::to_string(t_.back()) + "]");
    size_t i = std::upper_bound(t_.begin(), t_.end(), t) - t_.begin();
    i = std::clamp<size_t>(i, 1, t_.size() - 1);
    const double h = t_[i] - t_[i - 1], A = (t_[i] - t) / h, B = (t - t_[i - 1]) / h;
    MotionSample s;
    s.q = A * q_[i - 1] + B * q_[i] + ((A * A * A - A) * m_[i - 1] + (B * B * B - B) * m_[i]) * h * h / 6;
    s.qd = (q_[i] - q_[i - 1]) / h + ((1 - 3 * A * A) * m_[i - 1] + (3 * B * B - 1) * m_[i]) * h / 6;
    s.qdd = A * m_[i - 1] + B * m_[i];
    return s;
  }
  // The third derivative jumps at the nodes; steps end there unless a table is so dense that the
  // forced ends would cost more than the error control that follows the jumps anyway.
  std::vector<double> breakpoints() const override { return t_.size() <= kMaxTableBreakpoints ? t_ : std::vector<double>{}; }

 private:
  std::vector<double> t_, q_, m_;
};

class ConstantTorque : public TorqueLaw {
 public:
  explicit ConstantTorque(double tau) : tau_(tau) { require_finite("torque: value", tau); }
  double at(double) const override { return tau_; }

 private:
  double tau_;
};

class LinearTorque : public TorqueLaw {
 public:
  LinearTorque(std::vector<double> t, std::vector<double> v) : t_(std::move(t)), v_(std::move(v)) {
    check_table(t_, v_);
    if (t_.size() < 2) throw std::invalid_argument("a tabulated torque needs at least 2 points");
    for (size_t i = 1; i < t_.size(); ++i)
      if (!(t_[i] > t_[i - 1])) throw std::invalid_argument("tabulated times must increase");
  }
  double at(double t) const override {
    if (t <= t_.front()) return v_.front();
    if (t >= t_.back()) return v_.back();
    const size_t i = std::upper_bound(t_.begin(), t_.end(), t) - t_.begin();
    const double w = (t - t_[i - 1]) / (t_[i] - t_[i - 1]);
    return (1 - w) * v_[i - 1] + w * v_[i];
  }
  std::vector<double> breakpoints() const override {  // kinks at the nodes (a dense table: see Spline)
    return t_.size() <= kMaxTableBreakpoints ? t_ : std::vector<double>{};
  }

 private:
  std::vector<double> t_, v_;
};

class SplineTorque : public TorqueLaw {
 public:
  SplineTorque(std::vector<double> t, std::vector<double> tau) : s_(std::move(t), std::move(tau)) {}
  double at(double t) const override { return s_.at(t).q; }

 private:
  Spline s_;
};

class FunctionTorque : public TorqueLaw {
 public:
  FunctionTorque(std::function<double(double)> f, std::vector<double> b) : f_(std::move(f)), b_(std::move(b)) {}
  double at(double t) const override { return f_(t); }
  std::vector<double> breakpoints() const override { return b_; }

 private:
  std::function<double(double)> f_;
  std::vector<double> b_;
};

class PdTorque : public TorqueLaw {
 public:
  PdTorque(std::shared_ptr<MotionLaw> ref, double kp, double kd, std::shared_ptr<TorqueLaw> ff)
      : ref_(std::move(ref)), ff_(std::move(ff)), kp_(kp), kd_(kd) {
    if (!ref_) throw std::invalid_argument("a PD law needs a reference motion");
    if (!(kp_ >= 0.0) || !(kd_ >= 0.0)) throw std::invalid_argument("PD gains must not be negative");
    require_finite("pd: kp", kp_);
    require_finite("pd: kd", kd_);
  }
  double at(double t) const override { return ff_ ? ff_->at(t) : 0.0; }
  double at(double t, double q, double v) const override {
    const MotionSample r = ref_->at(t);
    return at(t) + kp_ * (r.q - q) + kd_ * (r.qd - v);
  }
  double stiffness() const override { return kp_; }
  double damping() const override { return kd_; }
  std::vector<double> breakpoints() const override {
    std::vector<double> b = ref_->breakpoints();
    if (ff_) {
      const auto f = ff_->breakpoints();
      b.insert(b.end(), f.begin(), f.end());
    }
    return b;
  }

 private:
  std::shared_ptr<MotionLaw> ref_;
  std::shared_ptr<TorqueLaw> ff_;
  double kp_, kd_;
};

}  // namespace

std::shared_ptr<TorqueLaw> pd_law(std::shared_ptr<MotionLaw> reference, double kp, double kd,
                                  std::shared_ptr<TorqueLaw> feedforward) {
  return std::make_shared<PdTorque>(std::move(reference), kp, kd, std::move(feedforward));
}

namespace {

class SampledTorque : public TorqueLaw {
 public:
  SampledTorque(std::shared_ptr<TorqueLaw> law, double ts, int delay) : law_(std::move(law)), ts_(ts), delay_(delay) {
    if (!law_) throw std::invalid_argument("a sampled law needs a law");
    if (!(ts_ > 0) || !std::isfinite(ts_)) throw std::invalid_argument("sample_time must be positive");
    if (delay_ < 0) throw std::invalid_argument("delay must be a whole number of samples, 0 or more");
  }
  double at(double) const override { return held_; }
  double at(double, double, double) const override { return held_; }
  double sample_time() const override { return ts_; }
  void sample(double t, double q, double v) override {
    // Once per sample time: a run going on from a saved state stands at a sample it has taken.
    if (t <= last_ + 1e-12 * std::max(1.0, std::abs(t))) return;
    last_ = t;
    const double u = law_->at(t, q, v);
    if (t <= 0.0) {  // a run's first sample: the controller at rest before it
      pending_.clear();
      held_ = u;
    }
    pending_.push_back(u);
    if (pending_.size() > static_cast<size_t>(delay_)) {
      held_ = pending_.front();
      pending_.pop_front();
    }
  }
  std::vector<double> memory() const override {
    std::vector<double> m = {last_, held_};
    m.insert(m.end(), pending_.begin(), pending_.end());
    return m;
  }
  void restore(const std::vector<double>& m) override {
    if (m.size() < 2 || m.size() > 2 + static_cast<size_t>(delay_))
      throw std::invalid_argument("a digital law's memory of " + std::to_string(m.size()) + " values does not fit its delay of " +
                                  std::to_string(delay_) + " samples");
    last_ = m[0];
    held_ = m[1];
    pending_.assign(m.begin() + 2, m.end());
  }

 private:
  std::shared_ptr<TorqueLaw> law_;
  double ts_;
  int delay_;
  double last_ = -INFINITY;  // the last sample's time
  double held_ = 0.0;
  std::deque<double> pending_;
};

}  // namespace

std::vector<double> pack_law_memory(const std::vector<JointInput>& inputs) {
  std::vector<double> x;
  bool any = false;
  for (const JointInput& in : inputs) {
    const std::vector<double> m = in.torque ? in.torque->memory() : std::vector<double>{};
    x.push_back(static_cast<double>(m.size()));
    x.insert(x.end(), m.begin(), m.end());
    any |= !m.empty();
  }
  return any ? x : std::vector<double>{};
}

void restore_law_memory(const std::vector<JointInput>& inputs, const std::vector<double>& x) {
  size_t i = 0;
  for (const JointInput& in : inputs) {
    if (i >= x.size() || !(x[i] >= 0) || x[i] != std::floor(x[i]) || x[i] > static_cast<double>(x.size() - i - 1))
      throw std::invalid_argument("the laws' memory does not fit these joints");
    const auto k = static_cast<size_t>(x[i++]);
    const std::vector<double> m(x.begin() + static_cast<long>(i), x.begin() + static_cast<long>(i + k));
    if (in.torque) in.torque->restore(m);
    else if (k > 0) throw std::invalid_argument("the laws' memory does not fit these joints");
    i += k;
  }
  if (i != x.size()) throw std::invalid_argument("the laws' memory does not fit these joints");
}

std::shared_ptr<TorqueLaw> sampled_law(std::shared_ptr<TorqueLaw> law, double sample_time, int delay) {
  return std::make_shared<SampledTorque>(std::move(law), sample_time, delay);
}

std::shared_ptr<MotionLaw> deployment_law(double psi0, double alpha, double T) {
  return std::make_shared<Deployment>(psi0, alpha, T);
}
std::shared_ptr<MotionLaw> spinup_law(double theta0, double Omega, double T) {
  return std::make_shared<Spinup>(theta0, Omega, T);
}
std::shared_ptr<MotionLaw> constant_rate_law(double q0, double rate) { return std::make_shared<ConstantRate>(q0, rate); }
std::shared_ptr<MotionLaw> tabulated_motion(std::vector<double> t, std::vector<double> q) {
  return std::make_shared<Spline>(std::move(t), std::move(q));
}
std::shared_ptr<TorqueLaw> constant_torque(double tau) { return std::make_shared<ConstantTorque>(tau); }
std::shared_ptr<TorqueLaw> tabulated_torque(std::vector<double> t, std::vector<double> tau) {
  return std::make_shared<LinearTorque>(std::move(t), std::move(tau));
}
std::shared_ptr<TorqueLaw> spline_torque(std::vector<double> t, std::vector<double> tau) {
  return std::make_shared<SplineTorque>(std::move(t), std::move(tau));
}
std::shared_ptr<TorqueLaw> torque_function(std::function<double(double)> f, std::vector<double> breakpoints) {
  return std::make_shared<FunctionTorque>(std::move(f), std::move(breakpoints));
}

void read_csv_series(const std::string& path, std::vector<double>& t, std::vector<double>& v) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open tabulated input");
  t.clear();
  v.clear();
  auto where = [&](int ln) { return path + ":" + std::to_string(ln) + ": "; };
  // A field is a number only if strtod takes all of it ("1OO" is not 100).
  auto number = [](const std::string& f, double& x) {
    if (f.empty()) return false;
    char* end = nullptr;
    errno = 0;
    x = std::strtod(f.c_str(), &end);
    return end == f.c_str() + f.size() && errno != ERANGE;
  };
  bool seen_content = false;
  std::string line;
  for (int ln = 1; std::getline(in, line); ++ln) {
    if (ln == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);  // a UTF-8 byte-order mark
    const auto hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    // Fields: separated by commas (white space around them ignored), or by white space alone.
    std::vector<std::string> fields;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    if (line.find(',') != std::string::npos) {
      std::stringstream ss(line);
      for (std::string f; std::getline(ss, f, ',');) {
        const auto x = f.find_first_not_of(" \t\r"), y = f.find_last_not_of(" \t\r");
        fields.push_back(x == std::string::npos ? std::string() : f.substr(x, y - x + 1));
      }
      if (line.back() == ',') fields.emplace_back();  // (getline drops a last empty field)
    } else {
      std::istringstream ss(line);
      for (std::string f; ss >> f;) fields.push_back(f);
    }
    // The first content line may be a header: words only, no field that starts like a number.
    if (!seen_content) {
      seen_content = true;
      const bool words = std::all_of(fields.begin(), fields.end(), [](const std::string& x) {
        return !x.empty() && !std::isdigit(static_cast<unsigned char>(x[0])) && x[0] != '-' && x[0] != '+' && x[0] != '.';
      });
      if (words) continue;
    }
    if (fields.size() != 2)
      throw std::runtime_error(where(ln) + "expected two numbers 'time, value' (got " + std::to_string(fields.size()) + " fields)");
    double a = 0.0, b = 0.0;
    for (int k = 0; k < 2; ++k)
      if (!number(fields[k], k == 0 ? a : b))
        throw std::runtime_error(where(ln) + "expected two numbers 'time, value' ('" + fields[k] + "' is not a number)");
    if (!std::isfinite(a) || !std::isfinite(b)) throw std::runtime_error(where(ln) + "not finite");
    if (!t.empty() && !(a > t.back()))
      throw std::runtime_error(where(ln) + "the times must increase (" + std::to_string(a) + " s after " +
                               std::to_string(t.back()) + " s)");
    t.push_back(a);
    v.push_back(b);
  }
  if (t.size() < 2) throw std::runtime_error(path + ": a table needs at least two rows");
}

}  // namespace rfem
