#pragma once
// Hostile glTF files for the CLI tests (SECURITY.md): dir/secret.bin and dir/secret.png lie
// outside dir/assets/, the assets' directory; dir/assets/link.bin is a link leading out; each
// evil-*.gltf reaches one of them a different way. ok.gltf reads ok.bin beside it.
#include "../io/gltf_builder.hpp"

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace sdfkit::test {

struct HostileAssets {
  std::filesystem::path assets;
  std::string secret_bin, secret_png;
  // (file, the URI its error message must name)
  std::vector<std::pair<std::filesystem::path, std::string>> evil;
  std::filesystem::path ok;
};

inline HostileAssets make_hostile_assets(const std::filesystem::path& dir,
                                         const std::string& asset_dir = "assets") {
  namespace fs = std::filesystem;
  GltfBuilder b;
  const int pos = b.positions({0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1});
  const int idx = b.indices(std::vector<std::uint16_t>{0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3});
  b.mesh("{\"attributes\":{\"POSITION\":" + std::to_string(pos) + "},\"indices\":" + std::to_string(idx) + "}");
  b.node("{\"mesh\":0}");
  const std::string scene = "\"scene\":0,\"scenes\":[{\"nodes\":[0]}]";
  HostileAssets h;
  h.assets = dir / asset_dir;
  fs::create_directories(h.assets);
  auto write = [](const fs::path& p, const std::string& bytes) {
    std::ofstream(p, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  };
  h.secret_bin = (dir / "secret.bin").string();
  h.secret_png = (dir / "secret.png").string();
  write(h.secret_bin, b.bin());  // the right size: it would load, were it read
  write(h.secret_png, "\x89PNG SECRET-IMAGE-BYTES");
  fs::create_symlink("../secret.bin", h.assets / "link.bin");
  write(h.assets / "ok.bin", b.bin());
  h.ok = h.assets / "ok.gltf";
  write(h.ok, b.json("ok.bin", scene));
  const std::vector<std::pair<std::string, std::string>> buffers = {
      {"evil-relative.gltf", "../secret.bin"},
      {"evil-absolute.gltf", h.secret_bin},
      {"evil-link.gltf", "link.bin"}};
  for (const auto& [name, uri] : buffers) {
    write(h.assets / name, b.json(uri, scene));
    h.evil.emplace_back(h.assets / name, uri);
  }
  GltfBuilder image = b;
  image.extra("\"images\":[{\"uri\":\"../secret.png\"}]");
  write(h.assets / "evil-image.gltf", image.json("ok.bin", scene));
  h.evil.emplace_back(h.assets / "evil-image.gltf", "../secret.png");
  return h;
}

}  // namespace sdfkit::test
