#pragma once
// The ESDIRK integrator (solvers/esdirk.cpp) as a stepper (solvers/stepper.hpp): its state, the
// step-size history included, carried from one advance() to the next.
#include <memory>

#include "stepper.hpp"

namespace rfem {

class EsdirkStepper final : public Stepper {
 public:
  /// Shares the equations (the caller keeps them alive); throws std::invalid_argument for an
  /// unusable table.
  EsdirkStepper(EquationsOfMotion& eq, const IntegratorOptions& opts);
  ~EsdirkStepper();
  EsdirkStepper(EsdirkStepper&&) noexcept;
  EsdirkStepper& operator=(EsdirkStepper&&) = delete;
  EsdirkStepper(const EsdirkStepper&) = delete;
  EsdirkStepper& operator=(const EsdirkStepper&) = delete;

  RunStatus start(SampleEmitter& emit) override;
  RunStatus advance(double until, SampleEmitter& emit) override;
  void inputs_changed() override;
  void add_sampler(Sampler s) override;
  double time() const override;
  double t_reached() const override;
  const IntegratorStats& stats() const override;
  IntegratorState state() const override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rfem
