#pragma once
// Mesh files in and SDF fields out. Loading keeps every input vertex in input order (what the
// writers must reproduce) next to the welded Mesh the backends see; writing puts a field back
// into the input's own vertex order (or face order) in glTF/glb, PLY or plain text.
//
// Every problem with an input file is an InputError whose message is one line:
// "<path>: <problem>".

#include "sdfkit/core/mesh.hpp"
#include "sdfkit/core/sdf.hpp"

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include <cstdint>
#include <array>
#include <functional>
#include <iosfwd>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace sdfkit::io {

enum class Format { Gltf, Glb, Obj, Off, Ply, Txt };

// The format named by the path's extension, case-insensitive (.gltf, .glb, .obj, .off, .ply,
// .txt). Throws InputError "<path>: unknown extension '.xyz' (expected .gltf, .glb, .obj, .off,
// .ply)" otherwise. .txt is an output-only format: load_asset rejects it.
Format format_from_path(const std::string& path);

// The format named by the path's extension (case-insensitive), or nothing: what a caller with its
// own list of formats (an output's) checks before format_from_path's message.
std::optional<Format> format_of_extension(const std::string& path);

// Lower-case name of a format ("gltf", "off", ...).
const char* format_name(Format format);

// Defaults of the resource limits below (see SECURITY.md for the memory they bound).
inline constexpr std::uint64_t kDefaultMaxTriangles = 50'000'000;
inline constexpr std::uint64_t kDefaultMaxFileSize = std::uint64_t{2} << 30;  // 2 GiB

struct LoadOptions {
  // weld_tolerance's default: sdfkit::default_weld_tolerance of the input positions (1e-6 of the
  // larger of their bounding-box diagonal and largest coordinate), which merges seam duplicates
  // that differ by float rounding.
  static constexpr float kDefaultWeld = -1.0f;
  // Positions closer than this (model units, after glTF node transforms) become one welded
  // vertex; 0 welds bitwise-equal positions only; negative (kDefaultWeld) = the default above.
  // See sdfkit::weld.
  float weld_tolerance = kDefaultWeld;
  // Asset contents are untrusted (SECURITY.md). By default a glTF's external buffers and images
  // are read only from inside the asset's own directory (after resolving `..` and symbolic
  // links); absolute paths, parent escapes, URI schemes other than data: and links leading
  // outside are refused without being opened. true lifts this for trusted trees (relative URIs
  // still resolve against the asset's directory, absolute ones as they are).
  bool allow_external_paths = false;
  // An asset with more triangles than this is refused (InputError) as soon as a count is known,
  // before the engine allocates for it; vertices are limited to 3 x max_triangles. 0 = no limit.
  std::uint64_t max_triangles = kDefaultMaxTriangles;
  // A file larger than this (bytes: the asset, and each file a glTF references) is refused
  // before it is read. 0 = no limit.
  std::uint64_t max_file_size = kDefaultMaxFileSize;
};

// Throws InputError unless the options are usable (weld tolerance finite; limits as documented).
void validate_load_options(const LoadOptions& options);

// The tolerance `options` asks for on these positions (model units): weld_tolerance itself, or
// the default when it is negative.
float weld_tolerance_for(const LoadOptions& options, std::span<const glm::vec3> positions);

struct Asset {
  std::string path;
  Format format = Format::Off;
  // Every input vertex in world space (glTF: node transforms applied), in input order. For glTF:
  // the primitives of the scene in traversal order (depth first, children in order), each
  // primitive's vertex range concatenated; a mesh used by several nodes appears once per node.
  std::vector<glm::vec3> input_positions;
  // Triangles as indices into input_positions, in input order (polygons fan-triangulated,
  // strips and fans unrolled).
  std::vector<Triangle> input_triangles;
  // The welded mesh the backends see: same triangle count and order as input_triangles, each
  // piece wound coherently and outward (orient_outward; input_triangles keep the file's winding).
  Mesh mesh;
  // Faces of `mesh` wound against their input triangle by orient_outward.
  std::size_t flipped_faces = 0;
  // For each input vertex, its welded vertex in `mesh`.
  std::vector<std::uint32_t> input_to_welded;
  // The welding tolerance used (model units; 0 = bitwise-equal positions).
  float weld_tolerance = 0.0f;
  // How long loading took: "read" (parse and validate the file), "weld", "orient".
  std::vector<StageTiming> load_stages;
  // Things skipped or changed while loading ("skipped 2 LINES primitives"), also logged.
  std::vector<std::string> warnings;
  // Format-specific data the writers need to write the input back (for glTF: the parsed model
  // and the vertex range of each primitive instance); nullptr where not needed.
  std::shared_ptr<const void> source;
};

// Loads a mesh file (format by extension). Throws InputError with one line "<path>: <problem>"
// for a missing or unreadable file, a malformed or truncated file, indices out of range,
// non-finite coordinates, a file without any triangle, a glTF reference refused by the
// confinement above or an asset past options' limits.
Asset load_asset(const std::string& path, const LoadOptions& options = {});

// Extra geometry written into glTF outputs as a node of its own at the scene root (a
// skeleton): points in world units, lines and triangles between them. PLY and txt ignore it.
struct Overlay {
  std::string name;
  std::vector<glm::vec3> points;
  std::vector<std::array<std::uint32_t, 2>> lines;
  std::vector<Triangle> triangles;
};

struct WriteOptions {
  bool color = true;        // glTF COLOR_0, PLY red/green/blue from colormap(normalized value)
  bool normalized = false;  // .txt and PLY quality hold the [0,1] normalized value
  std::vector<Overlay> overlays;  // glTF only
  // A second UV set (glTF TEXCOORD_1, e.g. a skeleton texture mapping's atlas): per input
  // triangle, the UV of each of its corners, in glTF's convention ([0,1]², v = 0 at the top of
  // the image). Per corner, not per vertex, so that a triangle never interpolates across two
  // charts of an atlas: the writer splits every input vertex into one output vertex per distinct
  // UV its corners have (positions, _SDF and COLOR_0 copied), so the output stays a valid glTF
  // whose TEXCOORD_1 is continuous inside each chart. glTF numbers UV sets from 0 without gaps:
  // the fresh asset has none of its own, so TEXCOORD_0 is the same accessor. Only for a fresh
  // glTF (a non-glTF input): with a glTF input, PLY or txt output it is a UsageError. Empty: no
  // TEXCOORD_1.
  std::vector<std::array<glm::vec2, 3>> texcoord1;
};

// Throws UsageError (an InputError; the CLI exits 2) when a `domain` field cannot be written to
// `out_path` at all: unknown extension, OBJ/OFF (nowhere to put values), per-face values to glTF.
// Cheap: call it before computing; write_field checks the same.
void check_output(const std::string& out_path, SdfDomain domain);

// Writes `field` (computed on asset.mesh) to out_path; the format follows the extension:
//  - .gltf/.glb: per-vertex fields only. A glTF input is written back whole (materials,
//    textures, other attributes, extensions, node hierarchy) with, on every triangle primitive,
//    the attributes _SDF (FLOAT SCALAR, model units), _SDF_NORMALIZED ([0,1]) and, with
//    options.color, COLOR_0 (VEC3 float; an existing COLOR_0 is replaced, with a warning). A
//    mesh instanced by several nodes carries the values of the first node drawing it; a node
//    whose values differ draws a copy of the mesh with its own (io/solids.hpp). Other inputs get
//    a fresh minimal glTF: one mesh, one node, one buffer. Either output is one
//    self-contained file: a single buffer (the BIN chunk of a .glb, a base64 data URI in a
//    .gltf); images read from files or data URIs are stored in that buffer (.glb) or as data
//    URIs (.gltf); an image file that could not be read keeps its uri.
//  - .ply: binary little endian, the input vertices and triangles, `float quality` on vertices
//    (per-vertex field) or faces (per-face field), with options.color uchar red/green/blue.
//  - .txt: one value per line (%.9g), input vertex order or face order.
// The file is written atomically (write_file_atomically). Throws InputError for a field that
// does not fit the asset or a per-face field to glTF, Error for an I/O failure.
void write_field(const std::string& out_path, const Asset& asset, const SdfField& field,
                 const WriteOptions& options = {});
// The same with `mesh` in place of asset.mesh: for an asset that lent its mesh to a Session
// (run_compute). An asset whose input_positions, input_triangles and input_to_welded are all
// empty has the mesh as its input (welding merged nothing and the copy was dropped): written as
// .ply or .txt only.
void write_field(const std::string& out_path, const Asset& asset, const Mesh& mesh, const SdfField& field,
                 const WriteOptions& options = {});

// The colour map of every sdfkit output: t in [0,1] (clamped; NaN counts as 0) to linear RGB in
// [0,1]. A hue ramp at full saturation, as in the paper's figures: 0 = red (thin), 0.25 =
// yellow, 0.5 = green, 0.75 = cyan, 1 = blue (thick), linear in hue between those stops.
glm::vec3 colormap(float t);

// Runs `write` on a stream to a temporary file next to `path` ("<path>.tmp-XXXXXX"), flushes
// it and renames it over `path`. If `write` throws or any I/O step fails, the temporary file
// is removed, an existing file at `path` is untouched and the exception propagates (I/O
// failures as Error "<path>: <problem>").
void write_file_atomically(const std::string& path,
                           const std::function<void(std::ostream&)>& write);

// Writes 8-bit pixels (rows top to bottom, `channels` = 3 for RGB or 4 for RGBA) as a PNG file,
// atomically (write_file_atomically). The one PNG encoder of the library (stb_image_write).
// Throws Error for an empty or inconsistent image or a failed write.
void write_png(const std::string& path, int width, int height, int channels,
               std::span<const std::uint8_t> pixels);

}  // namespace sdfkit::io
