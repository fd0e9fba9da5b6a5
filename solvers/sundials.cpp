#include <ida/ida.h>

#include <stdexcept>

#include "rfem/solvers/sundials_impl.hpp"

namespace rfem::sundials {

Context::Context() {
#if SUNDIALS_VERSION_MAJOR >= 7
  const int flag = SUNContext_Create(SUN_COMM_NULL, &ctx_);
#else
  const int flag = SUNContext_Create(nullptr, &ctx_);
#endif
  if (flag != 0 || !ctx_) throw std::runtime_error("SUNContext_Create failed");
}

Context::~Context() {
  if (ctx_) SUNContext_Free(&ctx_);
}

int silence_ida(void* ida_mem, const Context& ctx) {
#if SUNDIALS_VERSION_MAJOR >= 7
  (void)ida_mem;
  return SUNContext_ClearErrHandlers(ctx.get());
#else
  (void)ctx;
  return IDASetErrHandlerFn(ida_mem, [](int, const char*, const char*, char*, void*) {}, nullptr);
#endif
}

}  // namespace rfem::sundials
