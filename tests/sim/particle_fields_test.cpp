// Per-particle fields declared once (sim/particle_fields.h): the store sorts, uploads and downloads what
// a stage declares, state files save and restore it, the VTU export shows it; files written before the
// declarations existed still load and resume as the build that wrote them did.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <numeric>
#include <sstream>

#include "sim/error.h"
#include "sim/json_text.h"
#include "sim/particle_export.h"
#include "sim/particle_store.h"
#include "sim/solver.h"
#include "sim/state_file.h"
#include "tests/test_support.h"

namespace thaw {
namespace {

namespace fs = std::filesystem;
using testing::ClSuite;

class ParticleFieldsTest : public ClSuite {};

// n particles on a line, each carrying the declared "tracer" = id / 2.
HostParticles tracer_particles(std::size_t n) {
  HostParticles p;
  p.resize(n);
  HostColumn tracer;
  tracer.spec.name = "tracer";
  tracer.spec.exported = true;
  tracer.bytes.resize(n * 4);
  for (std::size_t i = 0; i < n; ++i) {
    p.position[i] = {float(i), 0.f, 0.f, 1.f};
    p.velocity[i] = {0.f, float(i), 0.f, 0.f};
    p.id[i] = static_cast<std::uint32_t>(i);
    tracer.as<float>()[i] = 0.5f * float(i);
  }
  p.columns.push_back(std::move(tracer));
  return p;
}

TEST_F(ParticleFieldsTest, ADeclaredFieldIsSortedSavedResumedAndExported) {
  constexpr std::size_t n = 100;
  ParticleStore store(cl());
  for (const FieldSpec& f : core_fields()) store.add(f);
  store.add({"tracer", FieldType::Float32, 1, true, true});
  store.add({"tag", FieldType::UInt8, 1, true, false, 7});  // not in the host particles: starts at its fill
  store.allocate(n);
  EXPECT_NE(store.reorder_source().find("out_tracer[i] = v_tracer;"), std::string::npos);
  store.upload(tracer_particles(n));

  // Sort into reverse order: every field follows, the SoA copy too.
  std::vector<cl_uint> reverse(n);
  std::iota(reverse.rbegin(), reverse.rend(), 0u);
  cl::Buffer order(cl().context(), CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, n * 4, reverse.data());
  const cl_uint stride = n + 16;
  cl::Buffer soa(cl().context(), CL_MEM_READ_WRITE, std::size_t(stride) * 7 * 4);
  store.reorder(order, soa, stride);
  HostParticles sorted;
  store.download(sorted);
  ASSERT_EQ(sorted.size(), n);
  const HostColumn* tracer = sorted.column("tracer");
  const HostColumn* tag = sorted.column("tag");
  ASSERT_TRUE(tracer && tag);
  EXPECT_TRUE(tracer->spec.exported);
  std::vector<float> x(std::size_t(stride) * 7);
  cl().queue().enqueueReadBuffer(soa, CL_TRUE, 0, x.size() * 4, x.data());
  for (std::size_t i = 0; i < n; ++i) {
    ASSERT_EQ(sorted.id[i], n - 1 - i);
    ASSERT_EQ(tracer->as<float>()[i], 0.5f * float(sorted.id[i]));
    ASSERT_EQ(tag->as<std::uint8_t>()[i], 7);
    ASSERT_EQ(x[i], float(sorted.id[i]));               // the x block
    ASSERT_EQ(x[5 * stride + i], float(sorted.id[i]));  // the vy block
  }

  // Saved and read back with its spec; uploaded again, it comes back bit for bit.
  testing::TempDir dir("fields");
  SimState st;
  st.particles = sorted;
  st.scene_json = "{}";
  const std::string path = (dir.path() / "fields.state").string();
  write_state_file(path, st);
  const SimState back = read_state_file(path);
  for (const char* name : {"tracer", "tag"}) {
    const HostColumn* a = sorted.column(name);
    const HostColumn* b = back.particles.column(name);
    ASSERT_TRUE(b) << name;
    EXPECT_EQ(b->bytes, a->bytes) << name;
    EXPECT_EQ(b->spec.type, a->spec.type) << name;
    EXPECT_EQ(b->spec.width, a->spec.width) << name;
    EXPECT_EQ(b->spec.exported, a->spec.exported) << name;
  }
  store.upload(back.particles);
  HostParticles again;
  store.download(again);
  EXPECT_EQ(again.column("tracer")->bytes, tracer->bytes);
  EXPECT_EQ(again.position, sorted.position);

  // The export names it (exported), not "tag" (not exported).
  ParticleExporter exporter((dir.path() / "export").string());
  exporter.write(sorted, 0.0);
  std::ifstream in(dir.path() / "export" / "frame_000000.vtu", std::ios::binary);
  std::stringstream vtu;
  vtu << in.rdbuf();
  EXPECT_NE(vtu.str().find("Name=\"tracer\" NumberOfComponents=\"1\""), std::string::npos);
  EXPECT_EQ(vtu.str().find("Name=\"tag\""), std::string::npos);
}

TEST_F(ParticleFieldsTest, BadDeclarationsAreRefused) {
  ParticleStore store(cl());
  store.add({"tracer", FieldType::Float32, 1});
  EXPECT_THROW(store.add({"tracer", FieldType::Float32, 1}), Error);
  EXPECT_THROW(store.add({"two words", FieldType::Float32, 1}), Error);
  EXPECT_THROW(store.add({"1st", FieldType::Float32, 1}), Error);
  EXPECT_THROW(store.add({"rgb", FieldType::Float32, 3}), Error);
  EXPECT_THROW(store.allocate(10), Error) << "no position or velocity field";
}

// tests/sim/data/free-ice-cup.json run 30 steps by the build before fields were declared (commit
// b2a6a61: untyped sections, rigid ice's own body buffers), then 10 more from that file by the same build.
TEST_F(ParticleFieldsTest, AStateFileFromBeforeTheDeclarationsResumesAsItsBuildDid) {
  const fs::path data = fs::path(THAW_SOURCE_DIR) / "tests" / "sim" / "data";
  const SimState old = read_state_file((data / "written-by-b2a6a61.state").string());
  const Scene scene = scene_from_json(parse_json(old.scene_json));
  check_state(old, scene, "fixture");
  ASSERT_TRUE(old.particles.column("body") && old.particles.column("body_offset"));
  Solver s(cl(), scene, old);
  for (int k = 0; k < 10; ++k) s.step();
  const SimState want = read_state_file((data / "resumed-10-by-b2a6a61.state").string());
  const SimState got = s.state();
  EXPECT_EQ(got.step, want.step);
  EXPECT_EQ(got.time, want.time);
  EXPECT_EQ(got.particles.position, want.particles.position);
  EXPECT_EQ(got.particles.velocity, want.particles.velocity);
  EXPECT_EQ(got.particles.enthalpy, want.particles.enthalpy);
  EXPECT_EQ(got.particles.id, want.particles.id);
  EXPECT_EQ(got.particles.column("body")->bytes, want.particles.column("body")->bytes);
  EXPECT_EQ(got.particles.column("body_offset")->bytes, want.particles.column("body_offset")->bytes);
  EXPECT_EQ(got.rigid_bodies, want.rigid_bodies);
  // The budget gained outflow and inflow entries since (0 here: nothing left or came in).
  ASSERT_EQ(want.energy_budget.size(), 8u);
  ASSERT_EQ(got.energy_budget.size(), 10u);
  EXPECT_EQ(std::vector<double>(got.energy_budget.begin(), got.energy_budget.begin() + 8),
            want.energy_budget);
  EXPECT_EQ(got.energy_budget[8], 0.0);
  EXPECT_EQ(got.energy_budget[9], 0.0);
}

}  // namespace
}  // namespace thaw
