// The skinned animation as a .glb, and its playback as a glTF viewer evaluates it.

#include "sdfkit/pointcloud/skinning.hpp"

#include "sdfkit/core/error.hpp"

#include <nlohmann/json.hpp>
#include <glm/geometric.hpp>
#include <glm/gtc/type_ptr.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>

namespace sdfkit::pointcloud {
namespace {

constexpr int kFloat = 5126, kUByte = 5121, kShort = 5122, kUShort = 5123, kByte = 5120, kUInt = 5125;

struct BinWriter {
  std::vector<unsigned char> bin;
  nlohmann::json views = nlohmann::json::array();
  // Appends bytes as a new bufferView (4-byte aligned); returns its index.
  int view(const void* data, std::size_t bytes, int target = 0) {
    while (bin.size() % 4) bin.push_back(0);
    nlohmann::json v{{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", bytes}};
    if (target) v["target"] = target;
    const auto* p = static_cast<const unsigned char*>(data);
    bin.insert(bin.end(), p, p + bytes);
    views.push_back(v);
    return static_cast<int>(views.size()) - 1;
  }
};

// The four weights as unsigned bytes summing to exactly 255 (largest remainders).
std::array<std::uint8_t, 4> quantize_weights(const std::array<float, 4>& w) {
  std::array<int, 4> q{};
  std::array<float, 4> rem{};
  float sum = 0.0f;
  for (float x : w) sum += std::max(0.0f, x);
  int total = 0;
  for (int k = 0; k < 4; ++k) {
    const float x = sum > 0.0f ? std::max(0.0f, w[k]) / sum * 255.0f : (k == 0 ? 255.0f : 0.0f);
    q[k] = static_cast<int>(std::floor(x));
    rem[k] = x - static_cast<float>(q[k]);
    total += q[k];
  }
  while (total < 255) {
    const int k = static_cast<int>(std::max_element(rem.begin(), rem.end()) - rem.begin());
    ++q[k];
    rem[k] = -1.0f;
    ++total;
  }
  return {static_cast<std::uint8_t>(q[0]), static_cast<std::uint8_t>(q[1]), static_cast<std::uint8_t>(q[2]),
          static_cast<std::uint8_t>(q[3])};
}

std::int16_t snorm16(float x) { return static_cast<std::int16_t>(std::lround(std::clamp(x, -1.0f, 1.0f) * 32767.0f)); }

}  // namespace

std::size_t write_skinned_glb(const SkinnedAnimation& anim, const std::string& path) {
  const std::size_t V = anim.rest.size(), B = anim.bone_count(), F = anim.poses.size();
  if (V == 0 || B == 0 || F == 0) throw InputError("nothing to write: an empty animation");
  if (B > 255) throw InputError("at most 255 bones fit unsigned-byte joints");
  BinWriter w;
  nlohmann::json accessors = nlohmann::json::array();
  // Rest positions.
  glm::vec3 lo(std::numeric_limits<float>::infinity()), hi(-std::numeric_limits<float>::infinity());
  for (const glm::vec3& p : anim.rest) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  accessors.push_back({{"bufferView", w.view(anim.rest.data(), V * 12, 34962)}, {"componentType", kFloat},
                       {"count", V}, {"type", "VEC3"}, {"min", {lo.x, lo.y, lo.z}}, {"max", {hi.x, hi.y, hi.z}}});
  // Joints: the influences by decreasing weight; a slot of weight 0 gets joint 0 (the glTF
  // spec's recommendation: the validator warns about other unused joints).
  std::vector<std::array<std::uint8_t, 4>> joints(V), weights(V);
  for (std::size_t i = 0; i < V; ++i) {
    const std::array<std::uint8_t, 4> q = quantize_weights(anim.weights[i]);
    std::array<int, 4> order{0, 1, 2, 3};
    std::stable_sort(order.begin(), order.end(), [&](int x, int y) { return q[x] > q[y]; });
    for (int k = 0; k < 4; ++k) {
      weights[i][k] = q[order[k]];
      joints[i][k] = q[order[k]] > 0 ? anim.joints[i][order[k]] : 0;
    }
  }
  accessors.push_back({{"bufferView", w.view(joints.data(), V * 4, 34962)}, {"componentType", kUByte},
                       {"count", V}, {"type", "VEC4"}});
  accessors.push_back({{"bufferView", w.view(weights.data(), V * 4, 34962)}, {"componentType", kUByte},
                       {"normalized", true}, {"count", V}, {"type", "VEC4"}});
  // Inverse bind matrices (column-major, as glm stores them).
  std::vector<float> ibm(B * 16);
  for (std::size_t b = 0; b < B; ++b) {
    std::memcpy(ibm.data() + 16 * b, glm::value_ptr(anim.inverse_bind[b]), 64);
    ibm[16 * b + 3] = ibm[16 * b + 7] = ibm[16 * b + 11] = 0.0f;  // exactly affine
    ibm[16 * b + 15] = 1.0f;
  }
  const int ibm_accessor = static_cast<int>(accessors.size());
  accessors.push_back({{"bufferView", w.view(ibm.data(), ibm.size() * 4)}, {"componentType", kFloat},
                       {"count", B}, {"type", "MAT4"}});
  // Keyframe times.
  std::vector<float> times(F);
  for (std::size_t f = 0; f < F; ++f) times[f] = static_cast<float>(static_cast<double>(f) * anim.frame_time);
  const int time_accessor = static_cast<int>(accessors.size());
  accessors.push_back({{"bufferView", w.view(times.data(), F * 4)}, {"componentType", kFloat}, {"count", F},
                       {"type", "SCALAR"}, {"min", {times.front()}}, {"max", {times.back()}}});
  // Per joint: translations (float) and rotations (normalized shorts), one bufferView each kind.
  std::vector<float> trans(B * F * 3);
  std::vector<std::int16_t> rot(B * F * 4);
  for (std::size_t b = 0; b < B; ++b)
    for (std::size_t f = 0; f < F; ++f) {
      const BonePose& p = anim.poses[f][b];
      const glm::quat q = glm::normalize(p.rotation);
      float* t = trans.data() + 3 * (b * F + f);
      t[0] = p.translation.x;
      t[1] = p.translation.y;
      t[2] = p.translation.z;
      std::int16_t* r = rot.data() + 4 * (b * F + f);
      r[0] = snorm16(q.x);
      r[1] = snorm16(q.y);
      r[2] = snorm16(q.z);
      r[3] = snorm16(q.w);
    }
  const int trans_view = w.view(trans.data(), trans.size() * 4);
  const int rot_view = w.view(rot.data(), rot.size() * 2);
  nlohmann::json nodes = nlohmann::json::array(), samplers = nlohmann::json::array(),
                 channels = nlohmann::json::array(), joint_nodes = nlohmann::json::array(),
                 children = nlohmann::json::array();
  nodes.push_back({{"name", "particles"}, {"mesh", 0}, {"skin", 0}});
  nodes.push_back({{"name", "skeleton"}});
  for (std::size_t b = 0; b < B; ++b) {
    const int node = static_cast<int>(nodes.size());
    const BonePose& p = anim.poses[0][b];
    const glm::quat q = glm::normalize(p.rotation);
    nodes.push_back({{"name", "bone" + std::to_string(b)},
                     {"translation", {p.translation.x, p.translation.y, p.translation.z}},
                     {"rotation", {q.x, q.y, q.z, q.w}}});
    children.push_back(node);
    joint_nodes.push_back(node);
    const int ta = static_cast<int>(accessors.size());
    accessors.push_back({{"bufferView", trans_view}, {"byteOffset", b * F * 12}, {"componentType", kFloat},
                         {"count", F}, {"type", "VEC3"}});
    accessors.push_back({{"bufferView", rot_view}, {"byteOffset", b * F * 8}, {"componentType", kShort},
                         {"normalized", true}, {"count", F}, {"type", "VEC4"}});
    const int s = static_cast<int>(samplers.size());
    samplers.push_back({{"input", time_accessor}, {"output", ta}, {"interpolation", "LINEAR"}});
    samplers.push_back({{"input", time_accessor}, {"output", ta + 1}, {"interpolation", "LINEAR"}});
    channels.push_back({{"sampler", s}, {"target", {{"node", node}, {"path", "translation"}}}});
    channels.push_back({{"sampler", s + 1}, {"target", {{"node", node}, {"path", "rotation"}}}});
  }
  nodes[1]["children"] = children;
  while (w.bin.size() % 4) w.bin.push_back(0);
  nlohmann::json doc;
  doc["asset"] = {{"version", "2.0"}, {"generator", "sdfkit compress-animation"}};
  doc["scene"] = 0;
  doc["scenes"] = nlohmann::json::array({{{"nodes", {0, 1}}}});
  doc["nodes"] = nodes;
  doc["meshes"] = nlohmann::json::array(
      {{{"name", "particles"},
        {"primitives", nlohmann::json::array({{{"attributes", {{"POSITION", 0}, {"JOINTS_0", 1}, {"WEIGHTS_0", 2}}},
                                               {"mode", 0}}})}}});
  doc["skins"] = nlohmann::json::array({{{"inverseBindMatrices", ibm_accessor}, {"joints", joint_nodes}, {"skeleton", 1}}});
  doc["animations"] = nlohmann::json::array({{{"name", "simulation"}, {"samplers", samplers}, {"channels", channels}}});
  doc["accessors"] = accessors;
  doc["bufferViews"] = w.views;
  doc["buffers"] = nlohmann::json::array({{{"byteLength", w.bin.size()}}});
  std::string json = doc.dump();
  while (json.size() % 4) json.push_back(' ');
  const std::uint32_t total = static_cast<std::uint32_t>(12 + 8 + json.size() + 8 + w.bin.size());
  const std::string temp = path + ".tmp";
  {
    std::ofstream out(temp, std::ios::binary);
    if (!out) throw InputError("cannot write " + path);
    auto u32 = [&](std::uint32_t v) { out.write(reinterpret_cast<const char*>(&v), 4); };
    u32(0x46546C67u);  // "glTF"
    u32(2);
    u32(total);
    u32(static_cast<std::uint32_t>(json.size()));
    u32(0x4E4F534Au);  // "JSON"
    out.write(json.data(), static_cast<std::streamsize>(json.size()));
    u32(static_cast<std::uint32_t>(w.bin.size()));
    u32(0x004E4942u);  // "BIN\0"
    out.write(reinterpret_cast<const char*>(w.bin.data()), static_cast<std::streamsize>(w.bin.size()));
    if (!out.flush()) throw InputError("cannot write " + path);
  }
  std::error_code ec;
  std::filesystem::rename(temp, path, ec);
  if (ec) {
    std::filesystem::remove(temp, ec);
    throw InputError("cannot write " + path);
  }
  return total;
}

// ---- Playback ------------------------------------------------------------------------------------

namespace {

struct Glb {
  nlohmann::json doc;
  std::vector<unsigned char> bin;
};

Glb read_glb(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError("cannot open " + path);
  std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto u32 = [&](std::size_t at) {
    if (at + 4 > bytes.size()) throw InputError(path + ": truncated glb");
    std::uint32_t v;
    std::memcpy(&v, bytes.data() + at, 4);
    return v;
  };
  if (bytes.size() < 20 || u32(0) != 0x46546C67u || u32(4) != 2) throw InputError(path + ": not a glTF 2.0 glb");
  const std::uint32_t json_len = u32(12);
  if (u32(16) != 0x4E4F534Au || 20 + static_cast<std::size_t>(json_len) > bytes.size()) throw InputError(path + ": bad JSON chunk");
  Glb g;
  try {
    g.doc = nlohmann::json::parse(bytes.begin() + 20, bytes.begin() + 20 + json_len);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path + ": " + e.what());
  }
  const std::size_t at = 20 + json_len;
  if (at + 8 <= bytes.size()) {
    const std::uint32_t bin_len = u32(at);
    if (u32(at + 4) != 0x004E4942u || at + 8 + bin_len > bytes.size()) throw InputError(path + ": bad BIN chunk");
    g.bin.assign(bytes.begin() + static_cast<std::ptrdiff_t>(at + 8), bytes.begin() + static_cast<std::ptrdiff_t>(at + 8 + bin_len));
  }
  return g;
}

// An accessor's elements as floats (normalized integers decoded as the glTF spec says).
std::vector<float> read_accessor(const Glb& g, int index, int& components) {
  const auto& a = g.doc.at("accessors").at(static_cast<std::size_t>(index));
  static const std::map<std::string, int> kComponents{{"SCALAR", 1}, {"VEC2", 2}, {"VEC3", 3}, {"VEC4", 4}, {"MAT4", 16}};
  components = kComponents.at(a.at("type").get<std::string>());
  const int type = a.at("componentType");
  const bool normalized = a.value("normalized", false);
  const std::size_t count = a.at("count");
  const std::size_t csize = type == kFloat || type == kUInt ? 4 : (type == kShort || type == kUShort) ? 2 : 1;
  const auto& v = g.doc.at("bufferViews").at(a.at("bufferView").get<std::size_t>());
  const std::size_t offset = v.value("byteOffset", std::size_t{0}) + a.value("byteOffset", std::size_t{0});
  const std::size_t stride = v.value("byteStride", csize * static_cast<std::size_t>(components));
  if (count > 0 && offset + stride * (count - 1) + csize * static_cast<std::size_t>(components) > g.bin.size())
    throw InputError("accessor " + std::to_string(index) + " reads past the buffer");
  std::vector<float> out(count * static_cast<std::size_t>(components));
  for (std::size_t e = 0; e < count; ++e)
    for (int c = 0; c < components; ++c) {
      const unsigned char* p = g.bin.data() + offset + e * stride + static_cast<std::size_t>(c) * csize;
      float x = 0.0f;
      switch (type) {
        case kFloat: std::memcpy(&x, p, 4); break;
        case kUByte: x = normalized ? *p / 255.0f : *p; break;
        case kByte: { const auto s = static_cast<std::int8_t>(*p); x = normalized ? std::max(s / 127.0f, -1.0f) : s; break; }
        case kUShort: { std::uint16_t s; std::memcpy(&s, p, 2); x = normalized ? s / 65535.0f : s; break; }
        case kShort: { std::int16_t s; std::memcpy(&s, p, 2); x = normalized ? std::max(s / 32767.0f, -1.0f) : s; break; }
        case kUInt: { std::uint32_t s; std::memcpy(&s, p, 4); x = static_cast<float>(s); break; }
        default: throw InputError("unknown accessor component type " + std::to_string(type));
      }
      out[e * static_cast<std::size_t>(components) + static_cast<std::size_t>(c)] = x;
    }
  return out;
}

struct Trs {
  glm::vec3 t{0.0f}, s{1.0f};
  glm::quat r{1.0f, 0.0f, 0.0f, 0.0f};
  bool has_matrix = false;
  glm::mat4 m{1.0f};
  glm::mat4 local() const {
    if (has_matrix) return m;
    return glm::translate(glm::mat4(1.0f), t) * glm::mat4_cast(r) * glm::scale(glm::mat4(1.0f), s);
  }
};

}  // namespace

std::vector<std::vector<glm::vec3>> play_skinned_glb(const std::string& path) {
  const Glb g = read_glb(path);
  try {
    const auto& jnodes = g.doc.at("nodes");
    const std::size_t N = jnodes.size();
    std::vector<Trs> base(N);
    std::vector<int> parent(N, -1);
    int skinned = -1;
    for (std::size_t n = 0; n < N; ++n) {
      const auto& jn = jnodes[n];
      if (jn.contains("matrix")) {
        base[n].has_matrix = true;
        for (int k = 0; k < 16; ++k) glm::value_ptr(base[n].m)[k] = jn["matrix"][static_cast<std::size_t>(k)];
      }
      if (jn.contains("translation")) base[n].t = {jn["translation"][0], jn["translation"][1], jn["translation"][2]};
      if (jn.contains("scale")) base[n].s = {jn["scale"][0], jn["scale"][1], jn["scale"][2]};
      if (jn.contains("rotation"))
        base[n].r = glm::quat(jn["rotation"][3].get<float>(), jn["rotation"][0].get<float>(), jn["rotation"][1].get<float>(),
                              jn["rotation"][2].get<float>());
      for (const auto& c : jn.value("children", nlohmann::json::array())) parent.at(c.get<std::size_t>()) = static_cast<int>(n);
      if (skinned < 0 && jn.contains("mesh") && jn.contains("skin")) skinned = static_cast<int>(n);
    }
    if (skinned < 0) throw InputError(path + ": no skinned mesh node");
    const auto& skin = g.doc.at("skins").at(jnodes[static_cast<std::size_t>(skinned)].at("skin").get<std::size_t>());
    const auto& prim = g.doc.at("meshes").at(jnodes[static_cast<std::size_t>(skinned)].at("mesh").get<std::size_t>()).at("primitives").at(0);
    int c = 0;
    const std::vector<float> pos = read_accessor(g, prim.at("attributes").at("POSITION"), c);
    const std::vector<float> jnt = read_accessor(g, prim.at("attributes").at("JOINTS_0"), c);
    const std::vector<float> wgt = read_accessor(g, prim.at("attributes").at("WEIGHTS_0"), c);
    const std::vector<float> ibm = read_accessor(g, skin.at("inverseBindMatrices"), c);
    std::vector<int> joints;
    for (const auto& j : skin.at("joints")) joints.push_back(j);
    const std::size_t V = pos.size() / 3;
    // Samplers of the first animation.
    const auto& anim = g.doc.at("animations").at(0);
    struct Channel {
      int node;
      std::string path;
      std::vector<float> in, out;
      int comps;
      bool step;
    };
    std::vector<Channel> channels;
    for (const auto& ch : anim.at("channels")) {
      const auto& s = anim.at("samplers").at(ch.at("sampler").get<std::size_t>());
      Channel k;
      k.node = ch.at("target").at("node");
      k.path = ch.at("target").at("path");
      int one = 0;
      k.in = read_accessor(g, s.at("input"), one);
      k.out = read_accessor(g, s.at("output"), k.comps);
      k.step = s.value("interpolation", std::string("LINEAR")) == "STEP";
      if (s.value("interpolation", std::string("LINEAR")) == "CUBICSPLINE") throw InputError(path + ": CUBICSPLINE is not played back");
      channels.push_back(std::move(k));
    }
    if (channels.empty()) throw InputError(path + ": the animation has no channels");
    const std::vector<float> keys = channels[0].in;
    std::vector<std::vector<glm::vec3>> frames;
    for (float time : keys) {
      std::vector<Trs> local = base;
      for (const Channel& k : channels) {
        std::size_t i1 = static_cast<std::size_t>(std::lower_bound(k.in.begin(), k.in.end(), time) - k.in.begin());
        i1 = std::min(i1, k.in.size() - 1);
        const std::size_t i0 = i1 > 0 ? i1 - 1 : 0;
        const float span = k.in[i1] - k.in[i0];
        float u = span > 0.0f ? std::clamp((time - k.in[i0]) / span, 0.0f, 1.0f) : 1.0f;
        if (k.step) u = time >= k.in[i1] ? 1.0f : 0.0f;
        const float* a = k.out.data() + i0 * static_cast<std::size_t>(k.comps);
        const float* b = k.out.data() + i1 * static_cast<std::size_t>(k.comps);
        Trs& t = local.at(static_cast<std::size_t>(k.node));
        t.has_matrix = false;
        if (k.path == "translation") t.t = glm::mix(glm::vec3(a[0], a[1], a[2]), glm::vec3(b[0], b[1], b[2]), u);
        else if (k.path == "scale") t.s = glm::mix(glm::vec3(a[0], a[1], a[2]), glm::vec3(b[0], b[1], b[2]), u);
        else if (k.path == "rotation")
          t.r = glm::normalize(glm::slerp(glm::normalize(glm::quat(a[3], a[0], a[1], a[2])),
                                          glm::normalize(glm::quat(b[3], b[0], b[1], b[2])), u));
      }
      std::vector<glm::mat4> world(N);
      std::vector<std::uint8_t> done(N, 0);
      std::function<const glm::mat4&(std::size_t)> world_of = [&](std::size_t n) -> const glm::mat4& {
        if (!done[n]) {
          world[n] = parent[n] >= 0 ? world_of(static_cast<std::size_t>(parent[n])) * local[n].local() : local[n].local();
          done[n] = 1;
        }
        return world[n];
      };
      std::vector<glm::mat4> joint_matrix(joints.size());
      for (std::size_t j = 0; j < joints.size(); ++j) {
        glm::mat4 inv;
        std::memcpy(glm::value_ptr(inv), ibm.data() + 16 * j, 64);
        joint_matrix[j] = world_of(static_cast<std::size_t>(joints[j])) * inv;
      }
      std::vector<glm::vec3> pts(V);
      for (std::size_t v = 0; v < V; ++v) {
        const glm::vec4 p(pos[3 * v], pos[3 * v + 1], pos[3 * v + 2], 1.0f);
        glm::vec4 acc(0.0f);
        for (int k = 0; k < 4; ++k) {
          const float wk = wgt[4 * v + static_cast<std::size_t>(k)];
          if (wk == 0.0f) continue;
          acc += wk * (joint_matrix.at(static_cast<std::size_t>(jnt[4 * v + static_cast<std::size_t>(k)])) * p);
        }
        pts[v] = glm::vec3(acc);
      }
      frames.push_back(std::move(pts));
    }
    return frames;
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path + ": " + e.what());
  } catch (const std::out_of_range& e) {
    throw InputError(path + ": an index is out of range (" + std::string(e.what()) + ")");
  }
}

std::string report_json(const CompressionReport& r) {
  nlohmann::json j{{"frames", r.frames},
                   {"points", r.points},
                   {"bones", r.bones},
                   {"raw_bytes", r.raw_bytes},
                   {"compressed_bytes", r.compressed_bytes},
                   {"compression_ratio", r.ratio},
                   {"body_length", r.body_length},
                   {"rmse", r.rmse},
                   {"max_error", r.max_error},
                   {"rmse_percent_of_length", r.rmse_percent},
                   {"max_error_percent_of_length", r.max_percent},
                   {"kg_error", r.kg_error},
                   {"measured_by", "playing the written glb back (accessors, samplers, node hierarchy, inverse bind matrices, weights)"}};
  return j.dump(1);
}

}  // namespace sdfkit::pointcloud
