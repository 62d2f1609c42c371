#include "sdfkit/process.hpp"

#include <cstdlib>  // defines __GLIBC__ on glibc

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace sdfkit {

bool keep_freed_heap() {
#if defined(__GLIBC__)
  return mallopt(M_TRIM_THRESHOLD, 64 << 20) == 1;
#else
  return true;
#endif
}

}  // namespace sdfkit
