// The render graph's logic as plain data (no device): ordering, culling, versioning errors,
// barrier and layout derivation, transient aliasing, printing.

#include "sdfkit/vulkan/render_graph.hpp"

#include <gtest/gtest.h>

#include <algorithm>

namespace sdfkit::vk {
namespace {

const ImageInfo kColor{VK_FORMAT_R32G32B32A32_SFLOAT, 64, 64, 1};
const ImageInfo kDepth{VK_FORMAT_D32_SFLOAT, 64, 64, 1};

std::vector<std::string> order_of(const CompiledGraph& g) {
  std::vector<std::string> names;
  for (const auto& p : g.passes) names.push_back(p.name);
  return names;
}

const CompiledPass& pass_named(const CompiledGraph& g, const std::string& name) {
  for (const auto& p : g.passes)
    if (p.name == name) return p;
  throw std::runtime_error("no pass " + name);
}

std::string compile_error(const RenderGraph& g) {
  try {
    (void)g.compile();
  } catch (const GraphError& e) {
    return e.what();
  }
  return "";
}

TEST(RenderGraph, WriteThenSampleDerivesLayoutTransitionAndDependency) {
  RenderGraph g;
  auto img = g.create_image("normal", kColor);
  auto out = g.import_buffer("result", 256, {});
  auto draw = g.add_pass("draw", PassKind::Graphics);
  img = draw.color(img, LoadOp::Clear);
  auto use = g.add_pass("use", PassKind::Compute);
  use.sampled(img);
  use.storage_write(out);
  const CompiledGraph c = g.compile();
  ASSERT_EQ(order_of(c), (std::vector<std::string>{"draw", "use"}));

  // draw: undefined -> colour attachment.
  const auto& b0 = pass_named(c, "draw").barriers;
  ASSERT_EQ(b0.size(), 1u);
  EXPECT_EQ(b0[0].src.layout, VK_IMAGE_LAYOUT_UNDEFINED);
  EXPECT_EQ(b0[0].dst.layout, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL);

  // use: colour writes made visible to compute sampling, with the layout change.
  const auto& b1 = pass_named(c, "use").barriers;
  auto it = std::find_if(b1.begin(), b1.end(), [](const Barrier& b) { return b.image; });
  ASSERT_NE(it, b1.end());
  EXPECT_EQ(it->resource, "normal#1");
  EXPECT_EQ(it->src.stages, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT);
  EXPECT_TRUE(it->src.access & VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT);
  EXPECT_EQ(it->dst.stages, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT);
  EXPECT_EQ(it->dst.access, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
  EXPECT_EQ(it->src.layout, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL);
  EXPECT_EQ(it->dst.layout, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
}

TEST(RenderGraph, ReadAfterReadInSameLayoutNeedsNoBarrier) {
  RenderGraph g;
  auto img = g.create_image("img", kColor);
  auto out = g.import_buffer("out", 64, {});
  auto w = g.add_pass("write", PassKind::Graphics);
  img = w.color(img, LoadOp::Clear);
  auto r1 = g.add_pass("read1", PassKind::Compute);
  r1.sampled(img);
  out = r1.storage_write(out);
  auto r2 = g.add_pass("read2", PassKind::Compute);
  r2.sampled(img);
  out = r2.storage_read_write(out);
  const CompiledGraph c = g.compile();
  for (const Barrier& b : pass_named(c, "read2").barriers) EXPECT_FALSE(b.image) << b.resource;
  // ... but the buffer written by read1 and read-written by read2 needs a write-after-write barrier.
  const auto& b2 = pass_named(c, "read2").barriers;
  ASSERT_EQ(b2.size(), 1u);
  EXPECT_EQ(b2[0].src.access, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
}

TEST(RenderGraph, WriteAfterReadIsOrderedWithAnExecutionDependency) {
  RenderGraph g;
  auto img = g.import_image("ring", kColor, {});
  auto out = g.import_buffer("out", 64, {});
  auto reader = g.add_pass("reader", PassKind::Compute);
  reader.storage_read(img);
  out = reader.storage_write(out);
  auto writer = g.add_pass("writer", PassKind::Compute);
  img = writer.storage_write(img);
  const CompiledGraph c = g.compile();
  ASSERT_EQ(order_of(c), (std::vector<std::string>{"reader", "writer"}));
  const auto& b = pass_named(c, "writer").barriers;
  ASSERT_EQ(b.size(), 1u);
  EXPECT_EQ(b[0].src.stages, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT);
  EXPECT_EQ(b[0].src.access, 0u);  // nothing to make available after a read
}

TEST(RenderGraph, UnusedPassesAreCulledTransitivelyAndSideEffectsKept) {
  RenderGraph g;
  auto a = g.create_image("a", kColor);
  auto b = g.create_image("b", kColor);
  auto out = g.import_buffer("out", 64, {});
  auto p1 = g.add_pass("make_a", PassKind::Graphics);
  a = p1.color(a, LoadOp::Clear);
  auto p2 = g.add_pass("a_to_b", PassKind::Graphics);
  p2.sampled(a);
  b = p2.color(b, LoadOp::Clear);  // b is never read: p2 and then p1 are dead
  auto p3 = g.add_pass("query", PassKind::Compute);
  p3.side_effect();
  auto p4 = g.add_pass("export", PassKind::Compute);
  out = p4.storage_write(out);
  const CompiledGraph c = g.compile();
  EXPECT_EQ(order_of(c), (std::vector<std::string>{"query", "export"}));
  EXPECT_EQ(c.culled, (std::vector<std::string>{"make_a", "a_to_b"}));
}

// A write-only use starts a version independent of the earlier contents, so the earlier writer
// dies when nothing reads its version; a pass that writes only part of the buffer declares
// read-write, which keeps the earlier writer and orders it first.
TEST(RenderGraph, PartialWriteKeepsTheEarlierWriterOnlyWhenDeclaredReadWrite) {
  for (const bool read_write : {false, true}) {
    RenderGraph g;
    auto buf = g.create_buffer("half", 64);
    auto out = g.import_buffer("out", 64, {});
    auto first = g.add_pass("first_half", PassKind::Compute);
    buf = first.storage_write(buf);
    auto second = g.add_pass("second_half", PassKind::Compute);
    buf = read_write ? second.storage_read_write(buf) : second.storage_write(buf);
    auto consume = g.add_pass("consume", PassKind::Compute);
    consume.storage_read(buf);
    out = consume.storage_write(out);
    const CompiledGraph c = g.compile();
    if (read_write) {
      EXPECT_EQ(order_of(c), (std::vector<std::string>{"first_half", "second_half", "consume"}));
      EXPECT_TRUE(c.culled.empty());
    } else {
      EXPECT_EQ(order_of(c), (std::vector<std::string>{"second_half", "consume"}));
      EXPECT_EQ(c.culled, std::vector<std::string>{"first_half"});
    }
  }
}

TEST(RenderGraph, WriteToStaleVersionIsAnError) {
  RenderGraph g;
  auto x0 = g.create_image("x", kColor);
  auto p1 = g.add_pass("first", PassKind::Graphics);
  auto x1 = p1.color(x0, LoadOp::Clear);
  auto p2 = g.add_pass("second", PassKind::Graphics);
  p2.color(x1, LoadOp::Load);  // x#2
  auto p3 = g.add_pass("third", PassKind::Graphics);
  p3.color(x1, LoadOp::Load);  // stale
  EXPECT_EQ(compile_error(g), "pass 'third': write to stale version 'x#1' (the latest is 'x#2')");
}

TEST(RenderGraph, ReadingAVersionNothingWritesIsAnError) {
  RenderGraph g;
  auto depth_back = g.create_image("depth_back", kColor);
  auto out = g.import_buffer("samples", 64, {});
  auto p = g.add_pass("diameter", PassKind::Compute);
  p.sampled(depth_back);
  p.atomic(out);
  EXPECT_EQ(compile_error(g), "pass 'diameter' reads 'depth_back#0' that nothing writes");
}

TEST(RenderGraph, LoadingAnUnwrittenAttachmentIsAnErrorButClearingIsNot) {
  RenderGraph g;
  auto out = g.import_image("target", kColor, {});
  auto d = g.create_image("depth", kDepth);
  auto p = g.add_pass("draw", PassKind::Graphics);
  p.color(out, LoadOp::Load);  // imported: fine
  p.depth(d, LoadOp::Load);
  EXPECT_EQ(compile_error(g), "pass 'draw' reads 'depth#0' that nothing writes");

  RenderGraph g2;
  auto out2 = g2.import_image("target", kColor, {});
  auto d2 = g2.create_image("depth", kDepth);
  auto p2 = g2.add_pass("draw", PassKind::Graphics);
  p2.color(out2, LoadOp::Clear);
  p2.depth(d2, LoadOp::Clear);
  EXPECT_NO_THROW((void)g2.compile());
}

TEST(RenderGraph, CycleIsReportedWithBothPasses) {
  RenderGraph g;
  auto x = g.create_image("x", kColor);
  auto y = g.create_image("y", kColor);
  auto a = g.add_pass("A", PassKind::Graphics);
  auto b = g.add_pass("B", PassKind::Graphics);
  x = a.color(x, LoadOp::Clear);  // A writes x#1
  b.sampled(x);                   // B reads x#1: A before B
  y = b.color(y, LoadOp::Clear);  // B writes y#1
  a.sampled(y);                   // A reads y#1: B before A
  a.side_effect();
  const std::string e = compile_error(g);
  EXPECT_TRUE(e == "cycle detected between passes 'A' and 'B'" || e == "cycle detected between passes 'B' and 'A'") << e;
}

TEST(RenderGraph, MisuseOfResourceKindsIsAnError) {
  RenderGraph g;
  auto buf = g.create_buffer("buf", 64);
  auto img = g.create_image("img", kColor);
  auto p = g.add_pass("compute", PassKind::Compute);
  p.color(img, LoadOp::Clear);
  EXPECT_EQ(compile_error(g), "pass 'compute' is not a graphics pass but uses 'img' as color attachment");
  RenderGraph g2;
  auto buf2 = g2.create_buffer("buf", 64);
  auto p2 = g2.add_pass("p", PassKind::Compute);
  p2.sampled(ImageHandle{buf2.id});
  EXPECT_EQ(compile_error(g2), "pass 'p' uses buffer 'buf' as sampled");
  (void)buf;
}

TEST(RenderGraph, TransientsWithDisjointLifetimesAlias) {
  RenderGraph g;
  auto out = g.import_buffer("out", 64, {});
  auto t1 = g.create_image("t1", kColor);
  auto t2 = g.create_image("t2", kColor);
  auto t3 = g.create_image("t3", kColor);
  auto p1 = g.add_pass("p1", PassKind::Graphics);
  t1 = p1.color(t1, LoadOp::Clear);
  auto p2 = g.add_pass("p2", PassKind::Graphics);  // t1 -> t2
  p2.sampled(t1);
  t2 = p2.color(t2, LoadOp::Clear);
  auto p3 = g.add_pass("p3", PassKind::Graphics);  // t2 -> t3; t1 is dead, t3 can take its memory
  p3.sampled(t2);
  t3 = p3.color(t3, LoadOp::Clear);
  auto p4 = g.add_pass("p4", PassKind::Compute);
  p4.sampled(t3);
  out = p4.storage_write(out);
  const CompiledGraph c = g.compile();
  ASSERT_EQ(c.physical_of.size(), 4u);
  EXPECT_EQ(c.physical_of[1], c.physical_of[3]);  // t1 and t3 share
  EXPECT_NE(c.physical_of[1], c.physical_of[2]);  // t1 and t2 overlap in p2
  // Taking over t1's memory, t3 starts from UNDEFINED but waits for p2's reads of t1.
  const auto& b = pass_named(c, "p3").barriers;
  auto it = std::find_if(b.begin(), b.end(), [](const Barrier& x) { return x.resource == "t3#1"; });
  ASSERT_NE(it, b.end());
  EXPECT_EQ(it->src.layout, VK_IMAGE_LAYOUT_UNDEFINED);
  EXPECT_TRUE(it->src.stages & VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT);
  // Usage flags are the union over aliases.
  EXPECT_TRUE(c.physical[c.physical_of[1]].usage & VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT);
  EXPECT_TRUE(c.physical[c.physical_of[1]].usage & VK_IMAGE_USAGE_SAMPLED_BIT);
}

TEST(RenderGraph, ImportedImageIsLeftInItsFinalLayout) {
  RenderGraph g;
  ExternalImage ext;
  ext.initial = {VK_PIPELINE_STAGE_2_NONE, 0, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
  ext.final_layout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
  auto img = g.import_image("ring0", kColor, ext);
  auto p = g.add_pass("draw", PassKind::Graphics);
  img = p.color(img, LoadOp::Clear);
  const CompiledGraph c = g.compile();
  ASSERT_EQ(c.final_barriers.size(), 1u);
  EXPECT_EQ(c.final_barriers[0].src.layout, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL);
  EXPECT_EQ(c.final_barriers[0].dst.layout, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
  // The imported image's first use keeps its contents' layout as the old layout? No: it is
  // cleared, so the transition comes from its imported layout.
  ASSERT_EQ(c.passes[0].barriers.size(), 1u);
  EXPECT_EQ(c.passes[0].barriers[0].src.layout, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
}

// The depth peel's shape: a ring of three images, each layer reads the previous one.
TEST(RenderGraph, PeelRingOrdersLayersAndPrintsBarriers) {
  RenderGraph g;
  ImageHandle ring[3];
  for (int i = 0; i < 3; ++i) ring[i] = g.import_image("layer" + std::to_string(i), kColor, {});
  auto depth = g.create_image("depth", kDepth);
  auto samples = g.import_buffer("samples", 1024, {});
  for (int k = 1; k <= 4; ++k) {
    auto peel = g.add_pass("peel" + std::to_string(k), PassKind::Graphics);
    peel.sampled(ring[(k - 1) % 3]);
    depth = peel.depth(depth, LoadOp::Clear);
    ring[k % 3] = peel.color(ring[k % 3], LoadOp::Clear);
    auto diam = g.add_pass("diameter" + std::to_string(k), PassKind::Compute);
    diam.sampled(ring[(k - 1) % 3]);
    diam.sampled(ring[k % 3]);
    samples = diam.atomic(samples);
  }
  const CompiledGraph c = g.compile();
  EXPECT_EQ(order_of(c), (std::vector<std::string>{"peel1", "diameter1", "peel2", "diameter2", "peel3",
                                                   "diameter3", "peel4", "diameter4"}));
  // peel4 overwrites layer1, which diameter2 and peel3/diameter3... read: WAR against diameter2.
  const std::string text = c.describe();
  // The WAR barrier is listed under the pass it precedes.
  const std::size_t peel4 = text.find("peel4 [graphics]"), war = text.find("barrier before: layer1#2");
  ASSERT_NE(peel4, std::string::npos) << text;
  ASSERT_NE(war, std::string::npos) << text;
  EXPECT_GT(war, peel4) << text;
  EXPECT_EQ(text.find("\n", peel4), text.find("\n    barrier before:", peel4)) << text;
  EXPECT_NE(text.find("COLOR_ATTACHMENT_OPTIMAL -> SHADER_READ_ONLY_OPTIMAL"), std::string::npos) << text;
  EXPECT_GT(c.barrier_count(), 8u);
}

}  // namespace
}  // namespace sdfkit::vk

namespace sdfkit::vk {
namespace {

// A chain draw -> blur -> use, an unused pass, and an out-of-order declaration: the phases one
// by one.
struct PhaseGraph {
  RenderGraph g;
  PhaseGraph() {
    auto out = g.import_buffer("out", 64, {});
    auto a = g.create_image("a", kColor);
    auto b = g.create_image("b", kColor);
    auto unused = g.create_image("unused", kColor);
    auto draw = g.add_pass("draw", PassKind::Graphics);  // 0
    a = draw.color(a, LoadOp::Clear);
    auto idle = g.add_pass("idle", PassKind::Graphics);  // 1: nothing reads what it writes
    idle.color(unused, LoadOp::Clear);
    auto blur = g.add_pass("blur", PassKind::Graphics);  // 2
    blur.sampled(a);
    b = blur.color(b, LoadOp::Clear);
    auto use = g.add_pass("use", PassKind::Compute);  // 3
    use.sampled(b);
    use.storage_write(out);
  }
};

TEST(RenderGraphPhases, ValidateReportsSetupErrorsAndUnwrittenReads) {
  PhaseGraph ok;
  EXPECT_NO_THROW(GraphCompiler(ok.g).validate());
  RenderGraph bad;
  auto img = bad.create_image("img", kColor);
  auto p = bad.add_pass("reader", PassKind::Compute);
  p.sampled(img);
  EXPECT_THROW(GraphCompiler(bad).validate(), GraphError);
}

TEST(RenderGraphPhases, OrderCullsUnusedPassesAndSortsByDependencies) {
  PhaseGraph pg;
  const compile_phase::Order o = GraphCompiler(pg.g).order();
  EXPECT_EQ(o.passes, (std::vector<std::uint32_t>{0, 2, 3}));
  EXPECT_EQ(o.culled, (std::vector<std::uint32_t>{1}));
}

TEST(RenderGraphPhases, LifetimesSpanFirstToLastUseInExecutionOrder) {
  PhaseGraph pg;
  const GraphCompiler c(pg.g);
  const compile_phase::Lifetimes lt = c.lifetimes(c.order());
  // Resources: out 0, a 1, b 2, unused 3; positions in the order draw 0, blur 1, use 2.
  EXPECT_EQ(lt.first, (std::vector<int>{2, 0, 1, -1}));
  EXPECT_EQ(lt.last, (std::vector<int>{2, 1, 2, -1}));
  EXPECT_EQ(lt.usage[1], VkFlags{VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT});
  EXPECT_EQ(lt.usage[0], VkFlags{VK_BUFFER_USAGE_STORAGE_BUFFER_BIT});
}

TEST(RenderGraphPhases, AssignPhysicalAliasesOnlyDisjointLifetimes) {
  PhaseGraph pg;
  const GraphCompiler c(pg.g);
  compile_phase::Lifetimes lt = c.lifetimes(c.order());
  compile_phase::Physical ph = c.assign_physical(lt);
  EXPECT_NE(ph.physical_of[1], ph.physical_of[2]);  // a and b overlap in blur
  EXPECT_EQ(ph.physical_of[3], UINT32_MAX);         // never used
  EXPECT_TRUE(ph.physical[ph.physical_of[0]].imported);
  // Shift b's first use past a's last: they share.
  lt.first[2] = 2;
  ph = c.assign_physical(lt);
  EXPECT_EQ(ph.physical_of[1], ph.physical_of[2]);
}

TEST(RenderGraphPhases, DeriveBarriersFollowsTheOrderGiven) {
  PhaseGraph pg;
  const GraphCompiler c(pg.g);
  const compile_phase::Order o = c.order();
  const compile_phase::Physical ph = c.assign_physical(c.lifetimes(o));
  CompiledGraph out;
  c.derive_barriers(o, ph, out);
  ASSERT_EQ(out.passes.size(), 3u);
  EXPECT_EQ(out.passes[1].name, "blur");
  // blur samples a (colour attachment -> shader read) and clears b (undefined -> attachment).
  ASSERT_EQ(out.passes[1].barriers.size(), 2u);
  for (const Barrier& b : out.passes[1].barriers)
    EXPECT_EQ(b.dst.layout, b.physical == ph.physical_of[1] ? VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL
                                                              : VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL);
}

TEST(RenderGraphPhases, PassDeclaresOnlyTheVersionsItUses) {
  PhaseGraph pg;
  const CompiledGraph c = pg.g.compile();
  const CompiledPass& blur = c.passes[1];
  // Versions: out#0 0, a#0 1, b#0 2, unused#0 3, a#1 4 (draw), unused#1 5 (idle), b#1 6 (blur).
  // blur reads a#1 and writes b#1 from b#0.
  EXPECT_TRUE(pass_declares(blur, 4));
  EXPECT_TRUE(pass_declares(blur, 2));
  EXPECT_TRUE(pass_declares(blur, 6));
  EXPECT_FALSE(pass_declares(blur, 0));  // out: use's
  EXPECT_FALSE(pass_declares(blur, 1));  // a#0, drawn over by draw
  EXPECT_FALSE(pass_declares(blur, 5));
}

}  // namespace
}  // namespace sdfkit::vk

namespace sdfkit::vk {
namespace {

// A ring layer that lives across submissions: each graph starts from the layout the previous one
// left, and compile() says which layout this one leaves (execute() stores it), with no flag kept
// by the caller.
TEST(RenderGraphHistory, AHistoryImageCarriesItsLayoutFromGraphToGraph) {
  HistoryImage layer;  // never used: UNDEFINED
  const ImageInfo info{VK_FORMAT_R32G32_UINT, 64, 64, 2};
  for (int submission = 0; submission < 2; ++submission) {
    RenderGraph g;
    auto img = g.import_history("layer", info, layer);
    auto out = g.import_buffer("out", 64, {});
    auto peel = g.add_pass("peel", PassKind::Graphics);
    img = peel.color(img, LoadOp::Clear);
    auto diam = g.add_pass("diameter", PassKind::Compute);
    diam.sampled(img);
    diam.storage_write(out);
    const CompiledGraph c = g.compile();
    const Barrier& first = c.passes[0].barriers.at(0);
    EXPECT_EQ(first.src.layout, submission == 0 ? VK_IMAGE_LAYOUT_UNDEFINED : VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    ASSERT_EQ(c.history_layouts.size(), 1u);
    EXPECT_EQ(c.history_layouts[0].first, &layer);
    EXPECT_EQ(c.history_layouts[0].second, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    EXPECT_TRUE(c.final_barriers.empty());  // no transition at the end: the next graph starts from here
    for (const auto& [h, l] : c.history_layouts) h->layout = l;  // what execute() does
  }
}

// Passes declaring one query pool keep their declaration order and are never culled.
TEST(RenderGraphQueries, QueryPassesKeepTheirOrderAndSurviveCulling) {
  RenderGraph g;
  const QueryPoolHandle q = g.import_query_pool("occlusion", VK_NULL_HANDLE);
  auto reset = g.add_pass("reset", PassKind::Transfer);
  reset.queries(q);
  auto draw = g.add_pass("draw", PassKind::Graphics);
  draw.color(g.create_image("unused", kColor), LoadOp::Clear);  // nothing reads it
  draw.queries(q);
  const CompiledGraph c = g.compile();
  ASSERT_EQ(order_of(c), (std::vector<std::string>{"reset", "draw"}));
  EXPECT_EQ(c.passes[1].query_pools, (std::vector<std::uint32_t>{q.id}));
  RenderGraph bad;
  auto p = bad.add_pass("p", PassKind::Compute);
  p.queries(QueryPoolHandle{3});
  EXPECT_NE(compile_error(bad).find("invalid query pool handle"), std::string::npos);
}

}  // namespace
}  // namespace sdfkit::vk
