// libFuzzer harness: the batch manifest parser (expand_inputs on "@manifest"). The manifest is
// written into an empty private directory and may name itself; inputs naming other places
// ('/' or "..": an absolute path, a parent) are skipped, so that a run never walks the
// machine's file system (manifests are trusted: they may list any path; the parser must still
// stay finite on any text, e.g. a manifest that lists itself many times).
#include "sdfkit/batch.hpp"
#include "sdfkit/core/error.hpp"

#include "private_dir.hpp"

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <string>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string& dir = sdfkit::fuzz::private_dir("/tmp/sdfkit-fuzz-manifest-XXXXXX");
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  if (text.find('/') != std::string_view::npos || text.find("..") != std::string_view::npos)
    return -1;  // not added to the corpus
  const std::string manifest = dir + "/inputs.list";
  {
    std::ofstream out(manifest, std::ios::binary | std::ios::trunc);
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
    if (!out) std::abort();
  }
  try {
    for (const std::string& input : sdfkit::expand_inputs({"@" + manifest}))
      if (input.rfind(dir, 0) != 0) std::abort();  // only what the directory holds
  } catch (const sdfkit::InputError&) {
  }
  return 0;
}
