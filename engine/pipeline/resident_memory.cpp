#include "sdfkit/pipeline.hpp"

#include <fstream>
#include <string>

namespace sdfkit {

ResidentMemory resident_memory() {
  ResidentMemory m;
  std::ifstream status("/proc/self/status");
  std::string key;
  while (status >> key) {
    double kib = 0;
    if (key == "VmRSS:" && status >> kib) m.rss_mib = kib / 1024.0;
    else if (key == "VmHWM:" && status >> kib) m.peak_rss_mib = kib / 1024.0;
    status.ignore(1 << 12, '\n');
  }
  return m;
}

}  // namespace sdfkit
