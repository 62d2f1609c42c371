// The untrusted-asset options every command that loads assets shares (SECURITY.md).
#include "commands.hpp"

namespace sdfkit::cli {

void add_asset_options(CLI::App& cmd, io::LoadOptions& load) {
  cmd.add_flag("--allow-external-paths", load.allow_external_paths,
               "Let a glTF read buffers and images outside its own directory (absolute paths, "
               "'..', links leading out): only for trusted asset trees");
  cmd.add_option("--max-triangles", load.max_triangles,
                 "Refuse an asset with more triangles than this before allocating for it (0 = no "
                 "limit; vertices are limited to 3x)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd.add_option("--max-file-size", load.max_file_size,
                 "Refuse a file (an asset, or a file a glTF references) larger than this, in bytes "
                 "or with a unit (512M, 2G; 0 = no limit)")
      ->transform(CLI::AsSizeValue(false))
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
}

}  // namespace sdfkit::cli
