#pragma once
// The program's signal handling: while a SignalStop lives, SIGINT, SIGTERM and SIGHUP (a closed
// terminal) request a stop of
// its token (the run ends cleanly after the current step, its outputs kept) instead of killing the
// process; the previous handlers come back when it dies.
#include <signal.h>

#include "../solvers/run_status.hpp"

namespace rfem::app {

class SignalStop {
 public:
  explicit SignalStop(const StopToken& token);
  ~SignalStop();
  SignalStop(const SignalStop&) = delete;
  SignalStop& operator=(const SignalStop&) = delete;

 private:
  struct sigaction old_int_ {}, old_term_{}, old_hup_{};
};

}  // namespace rfem::app
