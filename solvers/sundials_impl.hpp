#pragma once
// The SUNDIALS calls that differ between 6.x (Debian 12's source package) and 7.x, in one place: a
// user on a newer distribution changes this file and sundials.cpp only. Private to the library.
#include <sundials/sundials_context.h>

#include <string>

namespace rfem::sundials {

/// A SUNDIALS context, freed with it (6.x: SUNContext_Create(NULL, …); 7.x: SUN_COMM_NULL).
class Context {
 public:
  Context();  ///< throws std::runtime_error if SUNDIALS cannot create one
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;
  SUNContext get() const { return ctx_; }

 private:
  SUNContext ctx_ = nullptr;
};

/// Keeps IDA from printing its own messages and keeps the last error's text in `*last` instead, for
/// the run's status (6.x: IDASetErrHandlerFn; 7.x: the context's error handlers). The handler never
/// throws (it runs inside IDA's C frames). Returns a SUNDIALS flag.
int capture_ida_messages(void* ida_mem, const Context& ctx, std::string* last);

}  // namespace rfem::sundials
