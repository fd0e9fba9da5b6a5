#include "rfem/version.hpp"

namespace rfem {

const char* build_description() { return RFEM_BUILD_DESCRIPTION; }

}  // namespace rfem
