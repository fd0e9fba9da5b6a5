#include <ida/ida.h>

#include <stdexcept>
#include <string>

#include "sundials_impl.hpp"

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

int capture_ida_messages(void* ida_mem, const Context& ctx, std::string* last) {
#if SUNDIALS_VERSION_MAJOR >= 7
  (void)ida_mem;
  if (const int flag = SUNContext_ClearErrHandlers(ctx.get()); flag != 0) return flag;
  return SUNContext_PushErrHandler(
      ctx.get(),
      [](int, const char*, const char*, const char* msg, SUNErrCode, void* data, SUNContext) {
        if (msg) *static_cast<std::string*>(data) = msg;  // (no allocation can fail usefully here)
      },
      last);
#else
  (void)ctx;
  return IDASetErrHandlerFn(
      ida_mem,
      [](int code, const char*, const char*, char* msg, void* data) {
        if (code < 0 && msg) *static_cast<std::string*>(data) = msg;  // errors, not IDA's warnings
      },
      last);
#endif
}

}  // namespace rfem::sundials
