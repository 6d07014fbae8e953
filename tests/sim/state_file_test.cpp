#include "sim/state_file.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <type_traits>

#include "sim/error.h"
#include "sim/solver.h"
#include "sim/substance_stage.h"
#include "tests/test_support.h"

namespace thaw {
namespace {

namespace fs = std::filesystem;

std::string read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void write_bytes(const fs::path& path, std::string_view bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

// Writes bits through memory: a float constant such as bit_cast<float>(0x7f812345) may be folded by
// the optimiser into a quiet NaN before the code under test ever sees it.
void set_bits(float& dst, std::uint32_t pattern) { std::memcpy(&dst, &pattern, sizeof dst); }

template <typename T>
auto bits(const T& v) {
  std::conditional_t<sizeof(T) == 8, std::uint64_t, std::uint32_t> b;
  std::memcpy(&b, &v, sizeof b);
  return b;
}

// Values chosen to catch any path that goes through float arithmetic or text: NaNs with payloads
// (quiet and signalling), negative zero, denormals, infinities.
SimState make_state(std::size_t n) {
  SimState s;
  s.step = 123456789012ull;
  s.time = 0.1 + 0.2;
  const std::uint64_t negative_denormal = 0x8000000000000001ull;
  std::memcpy(&s.dt, &negative_denormal, sizeof s.dt);
  s.clamped = 7;
  s.scene_json = R"({"name": "t\u00e9st", "spacing": 0.01})";
  s.particles.resize(n);
  const std::uint32_t specials[] = {0x7fc12345u, 0x7f812345u, 0xffc00001u,
                                    0x80000000u, 0x00000001u, 0xff800000u};
  for (std::size_t i = 0; i < n; ++i) {
    const float f = static_cast<float>(i);
    s.particles.position[i] = {0.1f * f, 0.0f, -0.0f, 1e-3f + f};
    set_bits(s.particles.position[i][1], specials[i % 6]);
    s.particles.velocity[i] = {0.0f, -f, 0.5f, 0.0f};
    set_bits(s.particles.velocity[i][0], specials[(i + 1) % 6]);
    s.particles.density[i] = 1000.0f + f;
    if (i % 2) set_bits(s.particles.density[i], specials[(i + 3) % 6]);
    s.particles.phase[i] = static_cast<std::uint8_t>(i % kPhaseCount);
    s.particles.material[i] = static_cast<std::uint8_t>(i * 37 % 256);
    s.particles.id[i] = static_cast<std::uint32_t>((n - 1 - i) * 2654435761u);
    s.particles.enthalpy[i] = {334000.0f - 1000.0f * f, 1e-3f * f};
  }
  if (n > 0) s.energy_budget = {1.5e6, -2.0, 3.0, 0.25, -1e-9, 0.0, 7.0, 4.0};
  return s;
}

template <typename T>
bool same_bytes(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

void expect_bit_identical(const SimState& a, const SimState& b) {
  EXPECT_EQ(a.step, b.step);
  EXPECT_EQ(bits(a.time), bits(b.time));
  EXPECT_EQ(bits(a.dt), bits(b.dt));
  EXPECT_EQ(a.clamped, b.clamped);
  EXPECT_EQ(a.scene_json, b.scene_json);
  EXPECT_TRUE(same_bytes(a.particles.position, b.particles.position));
  EXPECT_TRUE(same_bytes(a.particles.velocity, b.particles.velocity));
  EXPECT_TRUE(same_bytes(a.particles.density, b.particles.density));
  EXPECT_TRUE(same_bytes(a.particles.phase, b.particles.phase));
  EXPECT_TRUE(same_bytes(a.particles.material, b.particles.material));
  EXPECT_TRUE(same_bytes(a.particles.id, b.particles.id));
  EXPECT_TRUE(same_bytes(a.particles.enthalpy, b.particles.enthalpy));
  EXPECT_TRUE(same_bytes(a.energy_budget, b.energy_budget));
}

// Builds version-1 files section by section, independently of the writer, so tests can make files the
// writer never would (unknown, missing, short sections) and check the documented layout.
class FileBuilder {
 public:
  struct Section {
    std::string name;
    std::uint32_t flags;
    std::uint32_t element_size;
    std::uint64_t count;
    std::string bytes;
  };

  static Section section_of(const SimState& s, const std::string& name) {
    const HostParticles& p = s.particles;
    const std::uint64_t n = p.size();
    auto raw = [](const auto& v) {
      return std::string(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(v[0]));
    };
    if (name == "position") return {name, 1, 16, n, raw(p.position)};
    if (name == "velocity") return {name, 1, 16, n, raw(p.velocity)};
    if (name == "density") return {name, 1, 4, n, raw(p.density)};
    if (name == "phase") return {name, 1, 1, n, raw(p.phase)};
    if (name == "material") return {name, 1, 1, n, raw(p.material)};
    if (name == "enthalpy") return {name, 1, 8, n, raw(p.enthalpy)};
    // The run-wide energy account: flags required | global, its own count.
    if (name == "energy_budget") return {name, 3, 8, s.energy_budget.size(), raw(s.energy_budget)};
    return {name, 1, 4, n, raw(p.id)};
  }

  static std::vector<Section> sections_of(const SimState& s) {
    std::vector<Section> out;
    for (const char* name : {"position", "velocity", "density", "phase", "material", "id", "enthalpy"}) {
      out.push_back(section_of(s, name));
    }
    if (!s.energy_budget.empty()) out.push_back(section_of(s, "energy_budget"));
    return out;
  }

  static std::string build(const SimState& s, const std::vector<Section>& sections) {
    std::string body;
    for (const Section& c : sections) {
      u32(body, static_cast<std::uint32_t>(c.name.size()));
      body += c.name;
      u32(body, c.flags);
      u32(body, c.element_size);
      u64(body, c.count);
      body += c.bytes;
    }
    std::string out("\x89THAW\r\n\x1a", 8);
    u32(out, 1);
    u32(out, 0x01020304);
    u64(out, 88 + s.scene_json.size() + body.size() + 8);
    u64(out, s.particles.size());
    u64(out, s.step);
    u64(out, bits(s.time));
    u64(out, bits(s.dt));
    u64(out, s.clamped);
    u64(out, s.scene_json.size());
    u32(out, static_cast<std::uint32_t>(sections.size()));
    u32(out, 0);
    u64(out, fnv1a64(out));
    out += s.scene_json;
    out += body;
    u64(out, fnv1a64(out));
    return out;
  }

 private:
  static void u32(std::string& out, std::uint32_t v) {
    for (int i = 0; i < 4; ++i) out.push_back(static_cast<char>(v >> (8 * i)));
  }
  static void u64(std::string& out, std::uint64_t v) {
    for (int i = 0; i < 8; ++i) out.push_back(static_cast<char>(v >> (8 * i)));
  }
};

class StateFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("thaw_state_test_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::vector<std::string> entries() const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir_)) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
  }

  // The message of the thaw::Error that reading `path` throws; fails the test if it does not throw.
  static std::string read_error(const fs::path& path) {
    try {
      read_state_file(path.string());
    } catch (const Error& e) {
      return e.what();
    }
    ADD_FAILURE() << "reading " << path << " did not throw";
    return {};
  }

  fs::path dir_;
};

// Expects `message` to name `path` and to contain `what`.
#define EXPECT_ERROR_NAMES(message, path, what)                   \
  do {                                                            \
    const std::string m_ = (message);                             \
    EXPECT_NE(m_.find((path).string()), std::string::npos) << m_; \
    EXPECT_NE(m_.find(what), std::string::npos) << m_;            \
  } while (0)

TEST_F(StateFileTest, RoundTripIsBitIdentical) {
  const SimState state = make_state(50);
  const fs::path path = dir_ / "run.state";
  write_state_file(path.string(), state);
  const SimState back = read_state_file(path.string());
  expect_bit_identical(state, back);

  // Writing what was read gives the same bytes: nothing is lost or normalised on the way.
  const fs::path again = dir_ / "again.state";
  write_state_file(again.string(), back);
  EXPECT_EQ(read_bytes(path), read_bytes(again));
}

TEST_F(StateFileTest, SpecialFloatsSurviveExactly) {
  const SimState state = make_state(6);
  const fs::path path = dir_ / "s.state";
  write_state_file(path.string(), state);
  const SimState back = read_state_file(path.string());
  EXPECT_EQ(bits(back.particles.position[1][1]), 0x7f812345u);  // signalling NaN
  EXPECT_EQ(bits(back.particles.position[0][1]), 0x7fc12345u);  // quiet NaN payload
  EXPECT_EQ(bits(back.particles.position[0][2]), 0x80000000u);  // -0.0
  EXPECT_EQ(bits(back.dt), 0x8000000000000001ull);
}

TEST_F(StateFileTest, HeaderFieldsRoundTrip) {
  SimState state;
  state.step = std::numeric_limits<std::uint64_t>::max();
  state.time = 12.345678901234567;
  state.dt = 1e-5;
  state.clamped = 42;
  state.scene_json = std::string("{\"a\": \"\0binary\xff\"}", 17);
  const fs::path path = dir_ / "empty.state";
  write_state_file(path.string(), state);
  const SimState back = read_state_file(path.string());
  expect_bit_identical(state, back);
  EXPECT_EQ(back.particles.size(), 0u);
}

TEST_F(StateFileTest, LayoutMatchesTheDocumentedFormat) {
  const SimState state = make_state(9);
  const fs::path path = dir_ / "layout.state";
  write_state_file(path.string(), state);
  EXPECT_EQ(read_bytes(path), FileBuilder::build(state, FileBuilder::sections_of(state)));
}

TEST_F(StateFileTest, EveryFlippedByteAfterThePrefixIsAChecksumError) {
  const SimState state = make_state(3);
  const fs::path good = dir_ / "good.state";
  write_state_file(good.string(), state);
  const std::string bytes = read_bytes(good);
  const fs::path bad = dir_ / "bad.state";
  // Bytes 0..15 (magic, version, byte order) have their own, more specific errors, tested below.
  for (std::size_t at = 16; at < bytes.size(); ++at) {
    std::string corrupt = bytes;
    corrupt[at] = static_cast<char>(corrupt[at] ^ 0x10);
    write_bytes(bad, corrupt);
    const std::string message = read_error(bad);
    EXPECT_NE(message.find(bad.string()), std::string::npos) << "byte " << at << ": " << message;
    EXPECT_NE(message.find("checksum mismatch"), std::string::npos) << "byte " << at << ": " << message;
  }
}

TEST_F(StateFileTest, TruncatedFileSaysExpectedAndActualSize) {
  const fs::path path = dir_ / "t.state";
  write_state_file(path.string(), make_state(20));
  const std::string bytes = read_bytes(path);
  for (std::size_t keep : {bytes.size() - 1, bytes.size() / 2, std::size_t{100}}) {
    write_bytes(path, bytes.substr(0, keep));
    EXPECT_ERROR_NAMES(
        read_error(path), path,
        "truncated: expected " + std::to_string(bytes.size()) + " bytes, found " + std::to_string(keep));
  }
  for (std::size_t keep : {std::size_t{0}, std::size_t{5}, std::size_t{12}, std::size_t{40}}) {
    write_bytes(path, bytes.substr(0, keep));
    EXPECT_ERROR_NAMES(read_error(path), path,
                       "truncated: expected at least 88 bytes, found " + std::to_string(keep));
  }
}

TEST_F(StateFileTest, TrailingBytesAreRejected) {
  const fs::path path = dir_ / "long.state";
  write_state_file(path.string(), make_state(4));
  write_bytes(path, read_bytes(path) + "x");
  EXPECT_ERROR_NAMES(read_error(path), path, "trailing bytes");
}

TEST_F(StateFileTest, WrongMagicIsNotAStateFile) {
  const fs::path path = dir_ / "scene.json";
  write_bytes(path, "{\"this\": \"is a scene, not a state file, and it is long enough to have a header\"}");
  EXPECT_ERROR_NAMES(read_error(path), path, "not a thaw state file");
  write_bytes(path, "ab");
  EXPECT_ERROR_NAMES(read_error(path), path, "not a thaw state file");
}

TEST_F(StateFileTest, FutureVersionIsRejectedWithBothVersions) {
  const fs::path path = dir_ / "future.state";
  write_state_file(path.string(), make_state(4));
  std::string bytes = read_bytes(path);
  bytes[8] = 2;
  write_bytes(path, bytes);
  const std::string message = read_error(path);
  EXPECT_ERROR_NAMES(message, path, "unsupported format version 2");
  EXPECT_NE(message.find("reads version 1"), std::string::npos) << message;
}

TEST_F(StateFileTest, WrongByteOrderMarkerIsRejected) {
  const fs::path path = dir_ / "swapped.state";
  write_state_file(path.string(), make_state(4));
  std::string bytes = read_bytes(path);
  std::swap(bytes[12], bytes[15]);
  std::swap(bytes[13], bytes[14]);
  write_bytes(path, bytes);
  EXPECT_ERROR_NAMES(read_error(path), path, "byte-order marker");
}

TEST_F(StateFileTest, MissingFileIsNamed) {
  const fs::path path = dir_ / "nope.state";
  EXPECT_ERROR_NAMES(read_error(path), path, "No such file or directory");
}

TEST_F(StateFileTest, DirectoryIsNotAStateFile) {
  EXPECT_ERROR_NAMES(read_error(dir_), dir_, "not a regular file");
}

TEST_F(StateFileTest, UnknownRequiredSectionIsRefused) {
  const SimState state = make_state(5);
  auto sections = FileBuilder::sections_of(state);
  sections.push_back({"temperature", 1, 4, 5, std::string(20, '\0')});
  const fs::path path = dir_ / "newer.state";
  write_bytes(path, FileBuilder::build(state, sections));
  EXPECT_ERROR_NAMES(read_error(path), path, "unknown required section 'temperature'");
}

TEST_F(StateFileTest, UnknownOptionalSectionIsSkipped) {
  const SimState state = make_state(5);
  auto sections = FileBuilder::sections_of(state);
  sections.insert(sections.begin() + 2, {"neighbour_count", 0, 2, 5, std::string(10, '\x07')});
  const fs::path path = dir_ / "extra.state";
  write_bytes(path, FileBuilder::build(state, sections));
  expect_bit_identical(state, read_state_file(path.string()));
}

TEST_F(StateFileTest, MissingSectionIsNamed) {
  const SimState state = make_state(5);
  auto sections = FileBuilder::sections_of(state);
  sections.erase(sections.begin() + 5);  // id
  const fs::path path = dir_ / "noid.state";
  write_bytes(path, FileBuilder::build(state, sections));
  EXPECT_ERROR_NAMES(read_error(path), path, "missing required section 'id'");
}

TEST_F(StateFileTest, SectionOfTheWrongLengthIsInconsistent) {
  const SimState state = make_state(5);
  auto sections = FileBuilder::sections_of(state);
  sections[3].count = 4;
  sections[3].bytes.pop_back();
  const fs::path path = dir_ / "short.state";
  write_bytes(path, FileBuilder::build(state, sections));
  EXPECT_ERROR_NAMES(read_error(path), path, "array sizes inconsistent: section 'phase' has 4 elements");
}

TEST_F(StateFileTest, SectionWithTheWrongElementSizeIsRejected) {
  const SimState state = make_state(5);
  auto sections = FileBuilder::sections_of(state);
  sections[2].element_size = 8;
  sections[2].bytes += std::string(20, '\0');
  const fs::path path = dir_ / "wide.state";
  write_bytes(path, FileBuilder::build(state, sections));
  EXPECT_ERROR_NAMES(read_error(path), path, "section 'density' has elements of 8 bytes, expected 4");
}

TEST_F(StateFileTest, InvalidPhaseIsRejected) {
  SimState state = make_state(5);
  state.particles.phase[3] = 9;
  const fs::path path = dir_ / "phase.state";
  write_bytes(path, FileBuilder::build(state, FileBuilder::sections_of(state)));
  EXPECT_ERROR_NAMES(read_error(path), path, "particle 3 has phase 9");
}

TEST_F(StateFileTest, WriterRefusesInconsistentArrays) {
  SimState state = make_state(5);
  state.particles.density.pop_back();
  const fs::path path = dir_ / "x.state";
  try {
    write_state_file(path.string(), state);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_ERROR_NAMES(std::string(e.what()), path, "array sizes inconsistent");
  }
  EXPECT_TRUE(entries().empty());
}

TEST_F(StateFileTest, SuccessfulWriteLeavesOnlyTheFile) {
  const fs::path path = dir_ / "run.state";
  write_state_file(path.string(), make_state(10));
  write_state_file(path.string(), make_state(11));  // replaces
  EXPECT_EQ(entries(), std::vector<std::string>{"run.state"});
  EXPECT_EQ(read_state_file(path.string()).particles.size(), 11u);
}

TEST_F(StateFileTest, WriteIntoMissingDirectoryFails) {
  const fs::path path = dir_ / "no" / "such" / "dir" / "run.state";
  try {
    write_state_file(path.string(), make_state(3));
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_ERROR_NAMES(std::string(e.what()), path, "No such file or directory");
  }
  EXPECT_TRUE(entries().empty());
}

TEST_F(StateFileTest, WriteOverADirectoryFailsAndCleansUp) {
  const fs::path path = dir_ / "a_directory";
  fs::create_directory(path);
  try {
    write_state_file(path.string(), make_state(3));
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_ERROR_NAMES(std::string(e.what()), path, "rename");
  }
  EXPECT_EQ(entries(), std::vector<std::string>{"a_directory"});
  EXPECT_TRUE(fs::is_directory(path));
}

TEST_F(StateFileTest, FailedWriteKeepsThePreviousFile) {
  const fs::path path = dir_ / "run.state";
  const SimState first = make_state(8);
  write_state_file(path.string(), first);
  const std::string before = read_bytes(path);
  // A directory where the temp file must go makes the write fail even for root, which ignores modes.
  const fs::path blocker = dir_ / ("run.state.tmp." + std::to_string(::getpid()));
  fs::create_directory(blocker);
  EXPECT_THROW(write_state_file(path.string(), make_state(20)), Error);
  fs::remove(blocker);
  EXPECT_EQ(read_bytes(path), before);
  EXPECT_EQ(entries(), std::vector<std::string>{"run.state"});
  expect_bit_identical(first, read_state_file(path.string()));
}

TEST(Fnv1a64, KnownVectors) {
  // Reference values of the published FNV-1a 64-bit test suite.
  EXPECT_EQ(fnv1a64(""), 0xcbf29ce484222325ull);
  EXPECT_EQ(fnv1a64("a"), 0xaf63dc4c8601ec8cull);
  EXPECT_EQ(fnv1a64("foobar"), 0x85944171f73967e8ull);
}

}  // namespace
}  // namespace thaw

namespace thaw {
namespace {

// What a state holds against the scene's physics (issue 44: -1e300 kg of salt in 40 particles loaded and
// the books reported -2.4e39 kg; +1e300, the books and the energy budget at 1e300 loaded too; a section
// renamed from substance_salt to substance_xyzw loaded with no salt; a corrupted enthalpy ran until a
// force blew up, and the message blamed the time step). Each is refused naming the section and what is
// wrong; the state as a run leaves it passes.
class StatePhysics : public testing::ClSuite {};

TEST_F(StatePhysics, SubstancesBooksAndTemperaturesAreCheckedAgainstTheScene) {
  const Scene scene = load_scene("wash-the-plate", {"spacing=0.005"});
  Solver solver(cl(), scene, initial_state(scene));
  for (int k = 0; k < 10; ++k) solver.step();
  const SimState good = solver.state();
  EXPECT_NO_THROW(check_state(good, scene, "good"));
  const auto refused = [&](SimState s, const std::string& says) {
    try {
      check_state(s, scene, "bad.state");
      ADD_FAILURE() << "accepted; expected: " << says;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
      EXPECT_EQ(std::string(e.what()).rfind("bad.state: ", 0), 0u) << e.what();
    }
  };
  const std::string salt = substance_field(scene.substances[0].name).name;
  const auto holding = [&](SimState s, const std::string& field, double amount) {
    HostColumn* c = s.particles.column(field);
    for (std::size_t i = 0; c && i < s.particles.size(); ++i)
      if (s.particles.phase[i] == std::uint8_t(Phase::Water)) {
        c->as<Float2>()[i] = Float2{float(amount), 0.f};
        break;
      }
    return s;
  };
  ASSERT_NE(good.particles.column(salt), nullptr) << salt;
  refused(holding(good, salt, -1e30), "is negative");
  refused(holding(good, salt, 1e30), "more than the particle's own mass");
  // A little more salt than the books say: the books do not close.
  refused(holding(good, salt, 1e-9), "books do not close");
  SimState renamed = good;
  renamed.particles.column(salt)->spec.name = "substance_xyzw";
  refused(renamed, "section 'substance_xyzw': the scene declares no dissolved substance 'xyzw'");
  SimState books = good;
  books.substances[0] = -1e300;
  refused(books, "is negative");
  books.substances[0] = 1e300;
  refused(books, "books do not close");
  SimState budget = good;
  budget.energy_budget[0] = 1e300;
  refused(budget, "section 'energy_budget': the books do not close");
  SimState hot = good;
  hot.particles.enthalpy[0] = Float2{3e30f, 0.f};
  refused(hot, "section 'enthalpy', particle 0");
  hot.particles.enthalpy[0] = Float2{-1e9f, 0.f};
  refused(hot, "outside -273.15");
}

}  // namespace
}  // namespace thaw
