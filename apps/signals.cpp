#include "signals.hpp"

#include <atomic>

namespace rfem::app {

namespace {
std::atomic<std::atomic<int>*> g_flag{nullptr};  // the live token's flag
extern "C" void on_signal(int sig) {
  if (std::atomic<int>* f = g_flag.load()) f->store(sig);  // lock-free stores: safe in a handler
}
}  // namespace

SignalStop::SignalStop(const StopToken& token) {
  g_flag.store(token.flag());
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, &old_int_);
  sigaction(SIGTERM, &sa, &old_term_);
  sigaction(SIGHUP, &sa, &old_hup_);
}

SignalStop::~SignalStop() {
  sigaction(SIGINT, &old_int_, nullptr);
  sigaction(SIGTERM, &old_term_, nullptr);
  sigaction(SIGHUP, &old_hup_, nullptr);
  g_flag.store(nullptr);
}

}  // namespace rfem::app
