#include "sim/state_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <optional>
#include <sstream>
#include <type_traits>
#include <vector>

#include "sim/books.h"
#include "sim/error.h"
#include "sim/scene.h"
#include "sim/solver_constants.h"
#include "sim/substance_stage.h"
#include "sim/thermal.h"

namespace thaw {
namespace {

// "\x89" catches 7-bit transfers, "\r\n" newline translation, "\x1a" a DOS `type` — as in PNG.
constexpr std::array<char, 8> kMagic = {'\x89', 'T', 'H', 'A', 'W', '\r', '\n', '\x1a'};
constexpr std::uint32_t kByteOrderMark = 0x01020304;
constexpr std::uint32_t kSectionRequired = 1;
// A section of the run as a whole (its count is its own, not the particle count).
constexpr std::uint32_t kSectionGlobal = 2;
// A declared field's spec (sim/particle_fields.h) rides in the flags: bit 2 exported, bits 8-15 the
// element type (FieldType; 0 in files written before fields were declared), bits 16-23 its width.
constexpr std::uint32_t kSectionExported = 4;
constexpr std::uint32_t field_flags(const FieldSpec& f) {
  return (f.exported ? kSectionExported : 0u) | (std::uint32_t(f.type) << 8) | (std::uint32_t(f.width) << 16);
}
constexpr const char* kEnergySection = "energy_budget";
constexpr const char* kBodiesSection = "rigid_bodies";
constexpr const char* kLabellingSection = "rigid_labelling";
constexpr const char* kOutflowSection = "outflow";
constexpr const char* kInflowSection = "inflow";
constexpr const char* kSubstancesSection = "substances";
constexpr std::size_t kPrefixBytes = 8 + 4 + 4;  // magic, version, byte order: the same in every version
constexpr std::size_t kHeaderBytes = kPrefixBytes + 7 * 8 + 2 * 4 + 8;
constexpr std::size_t kTrailerBytes = 8;
constexpr std::size_t kMaxSectionName = 256;

std::string errno_text(int err) { return std::strerror(err); }

Error file_error(const std::string& path, const std::string& what) {
  return Error("state file '" + path + "': " + what);
}

// Copies `bytes` of arrays whose scalars are `word` bytes wide between host order and the file's
// little-endian order. A plain copy on little-endian hosts; memcpy keeps every bit (NaN payloads too).
void copy_little_endian(char* dst, const char* src, std::size_t bytes, std::size_t word) {
  if constexpr (std::endian::native == std::endian::little) {
    if (bytes != 0) std::memcpy(dst, src, bytes);
  } else {
    for (std::size_t at = 0; at < bytes; at += word) {
      for (std::size_t k = 0; k < word; ++k) dst[at + k] = src[at + word - 1 - k];
    }
  }
}

class ByteWriter {
 public:
  void u32(std::uint32_t v) { scalar(v); }
  void u64(std::uint64_t v) { scalar(v); }
  void f64(const double& v) { scalar(v); }
  void bytes(std::string_view b) { out_.append(b); }
  // A whole array at once: the state of a million particles encodes at memory speed.
  void words(const void* data, std::size_t bytes, std::size_t word) {
    const std::size_t at = out_.size();
    out_.resize(at + bytes);
    copy_little_endian(out_.data() + at, static_cast<const char*>(data), bytes, word);
  }
  void reserve(std::size_t n) { out_.reserve(n); }
  std::string& buffer() { return out_; }

 private:
  template <typename T>
  void scalar(const T& v) {
    words(&v, sizeof v, sizeof v);
  }
  std::string out_;
};

std::uint64_t load_u64(std::string_view data, std::size_t at) {
  std::uint64_t v;
  copy_little_endian(reinterpret_cast<char*>(&v), data.data() + at, sizeof v, sizeof v);
  return v;
}

std::uint32_t load_u32(std::string_view data, std::size_t at) {
  std::uint32_t v;
  copy_little_endian(reinterpret_cast<char*>(&v), data.data() + at, sizeof v, sizeof v);
  return v;
}

// Bounds-checked reads over a verified buffer; a failure here means a malformed (not corrupted) file.
class ByteReader {
 public:
  ByteReader(const std::string& path, std::string_view data, std::size_t pos)
      : path_(path), data_(data), pos_(pos) {}

  std::uint32_t u32() { return load_u32(bytes(4, "a field"), 0); }
  std::uint64_t u64() { return load_u64(bytes(8, "a field"), 0); }
  // Into the destination's memory, never through a float value the optimiser may canonicalise.
  void f64(double& dst) {
    copy_little_endian(reinterpret_cast<char*>(&dst), bytes(8, "a field").data(), 8, 8);
  }
  std::string_view bytes(std::uint64_t n, const std::string& what) {
    if (n > remaining()) {
      throw file_error(path_, "malformed: " + what + " needs " + std::to_string(n) + " bytes at offset " +
                                  std::to_string(pos_) + ", only " + std::to_string(remaining()) + " remain");
    }
    std::string_view b = data_.substr(pos_, static_cast<std::size_t>(n));
    pos_ += static_cast<std::size_t>(n);
    return b;
  }
  std::size_t pos() const { return pos_; }
  std::size_t remaining() const { return data_.size() - pos_; }

 private:
  const std::string& path_;
  std::string_view data_;
  std::size_t pos_;
};

std::string hex(std::uint64_t v) {
  char buf[19];
  std::snprintf(buf, sizeof buf, "0x%016llx", static_cast<unsigned long long>(v));
  return buf;
}

// Width of the scalars an element is made of, for byte order: a Float4 is four 4-byte words.
template <typename T>
constexpr std::size_t word_size() {
  if constexpr (std::is_same_v<T, Float4> || std::is_same_v<T, Float2>) {
    return sizeof(float);
  } else {
    static_assert(std::is_arithmetic_v<T>, "a section element is a scalar or a Float4");
    return sizeof(T);
  }
}

// Every per-particle array that a state file holds, with its section name. Fields added to
// HostParticles (temperature, enthalpy, body id) get a line here; readers of older versions then
// refuse the file by the section's required flag instead of resuming without the field.
template <typename Particles, typename Visit>
void for_each_array(Particles& p, Visit&& visit) {
  visit("position", p.position);
  visit("velocity", p.velocity);
  visit("density", p.density);
  visit("phase", p.phase);
  visit("material", p.material);
  visit("id", p.id);
  visit("enthalpy", p.enthalpy);
}

// Per-particle arrays that only some runs have: written when they hold one element per particle and
// not only zeros (a run without fixed ice has no anchored particles), left empty (anchored: all zero)
// when a file does not have them.
template <typename State, typename Visit>
void for_each_optional_array(State& s, Visit&& visit) {
  visit("anchored", s.particles.anchored);
}

// Fields that files written before fields were declared hold without a type in their flags: rigid ice's.
std::optional<FieldSpec> legacy_field(const std::string& name) {
  if (name == "body") return FieldSpec{"body", FieldType::UInt32, 1, true, true, 0xffffffffu};
  if (name == "body_offset") return FieldSpec{"body_offset", FieldType::Float32, 4};
  return std::nullopt;
}

template <typename Array>
bool worth_writing(const Array& array, std::size_t n) {
  using Element = std::remove_cvref_t<decltype(array[0])>;
  if (array.size() != n || n == 0) return false;
  if constexpr (std::is_same_v<Element, std::uint8_t>) {  // flags: all clear is the default
    return std::any_of(array.begin(), array.end(), [](Element e) { return e != Element(0); });
  } else {
    return true;
  }
}

// Global sections of doubles, written when not empty.
template <typename State, typename Visit>
void for_each_global(State& s, Visit&& visit) {
  visit(kEnergySection, s.energy_budget);
  visit(kBodiesSection, s.rigid_bodies);
  visit(kLabellingSection, s.rigid_labelling);
  visit(kOutflowSection, s.outflow);
  visit(kInflowSection, s.inflow);
  visit(kSubstancesSection, s.substances);
}

// The arrays of one HostParticles must agree in length before they are written.
std::optional<std::string> inconsistent_sizes(const HostParticles& p) {
  std::optional<std::string> problem;
  for_each_array(p, [&](const char* name, const auto& array) {
    if (!problem && array.size() != p.position.size()) {
      problem = "array sizes inconsistent: position has " + std::to_string(p.position.size()) +
                " elements, " + name + " has " + std::to_string(array.size());
    }
  });
  return problem;
}

}  // namespace

std::string encode_state(const SimState& s) {
  const HostParticles& p = s.particles;
  std::uint32_t sections = 0;
  std::size_t body = 0;
  for_each_array(p, [&](const char* name, const auto& array) {
    ++sections;
    body += 4 + std::strlen(name) + 4 + 4 + 8 + array.size() * sizeof(array[0]);
  });
  for_each_optional_array(s, [&](const char* name, const auto& array) {
    if (!worth_writing(array, p.size())) return;
    ++sections;
    body += 4 + std::strlen(name) + 4 + 4 + 8 + array.size() * sizeof(array[0]);
  });
  for (const HostColumn& c : p.columns) {
    if (!c.spec.saved) continue;
    ++sections;
    body += 4 + c.spec.name.size() + 4 + 4 + 8 + c.bytes.size();
  }
  for_each_global(s, [&](const char* name, const std::vector<double>& values) {
    if (values.empty()) return;
    ++sections;
    body += 4 + std::strlen(name) + 4 + 4 + 8 + values.size() * 8;
  });
  const std::size_t total = kHeaderBytes + s.scene_json.size() + body + kTrailerBytes;

  ByteWriter w;
  w.reserve(total);
  w.bytes(std::string_view(kMagic.data(), kMagic.size()));
  w.u32(kStateFileVersion);
  w.u32(kByteOrderMark);
  w.u64(total);
  w.u64(p.size());
  w.u64(s.step);
  w.f64(s.time);
  w.f64(s.dt);
  w.u64(s.clamped);
  w.u64(s.scene_json.size());
  w.u32(sections);
  w.u32(0);
  w.u64(fnv1a64(w.buffer()));

  w.bytes(s.scene_json);
  auto write_array = [&](const char* name, const auto& array) {
    using Element = std::remove_cvref_t<decltype(array[0])>;
    const std::size_t name_length = std::strlen(name);
    w.u32(static_cast<std::uint32_t>(name_length));
    w.bytes(std::string_view(name, name_length));
    w.u32(kSectionRequired);
    w.u32(sizeof(Element));
    w.u64(array.size());
    w.words(array.data(), array.size() * sizeof(Element), word_size<Element>());
  };
  for_each_array(p, write_array);
  for_each_optional_array(s, [&](const char* name, const auto& array) {
    if (worth_writing(array, p.size())) write_array(name, array);
  });
  for (const HostColumn& c : p.columns) {
    if (!c.spec.saved) continue;
    w.u32(static_cast<std::uint32_t>(c.spec.name.size()));
    w.bytes(c.spec.name);
    w.u32(kSectionRequired | field_flags(c.spec));
    w.u32(static_cast<std::uint32_t>(c.spec.bytes()));
    w.u64(c.size());
    w.words(c.bytes.data(), c.bytes.size(), scalar_bytes(c.spec.type));
  }
  for_each_global(s, [&](const char* name, const std::vector<double>& values) {
    if (values.empty()) return;
    const std::size_t name_length = std::strlen(name);
    w.u32(static_cast<std::uint32_t>(name_length));
    w.bytes(std::string_view(name, name_length));
    w.u32(kSectionRequired | kSectionGlobal);
    w.u32(8);
    w.u64(values.size());
    w.words(values.data(), values.size() * 8, 8);
  });
  w.u64(fnv1a64(w.buffer()));
  return std::move(w.buffer());
}

void for_each_state_section(const SimState& s,
                            const std::function<void(const std::string&, std::string_view)>& visit) {
  const HostParticles& p = s.particles;
  const auto bytes = [](const auto& array) {
    return std::string_view(reinterpret_cast<const char*>(array.data()), array.size() * sizeof(array[0]));
  };
  std::string header(40, '\0');
  const std::uint64_t n = p.size();
  std::memcpy(&header[0], &n, 8);
  std::memcpy(&header[8], &s.step, 8);
  std::memcpy(&header[16], &s.time, 8);
  std::memcpy(&header[24], &s.dt, 8);
  std::memcpy(&header[32], &s.clamped, 8);
  visit("header", header);
  for_each_array(p, [&](const char* name, const auto& array) { visit(name, bytes(array)); });
  for_each_optional_array(s, [&](const char* name, const auto& array) { visit(name, bytes(array)); });
  for (const HostColumn& c : p.columns)
    if (c.spec.saved) visit(c.spec.name, bytes(c.bytes));
  for_each_global(s,
                  [&](const char* name, const std::vector<double>& values) { visit(name, bytes(values)); });
}

namespace {

std::string read_whole_file(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw file_error(path, "cannot open: " + errno_text(errno));
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    const int err = errno;
    ::close(fd);
    throw file_error(path, "cannot stat: " + errno_text(err));
  }
  if (!S_ISREG(st.st_mode)) {
    ::close(fd);
    throw file_error(path, "not a regular file");
  }
  std::string data(static_cast<std::size_t>(st.st_size), '\0');
  std::size_t got = 0;
  while (got < data.size()) {
    const ssize_t r = ::read(fd, data.data() + got, data.size() - got);
    if (r < 0 && errno == EINTR) continue;
    if (r < 0) {
      const int err = errno;
      ::close(fd);
      throw file_error(path, "cannot read: " + errno_text(err));
    }
    if (r == 0) break;  // shrank while reading; the size checks below report it
    got += static_cast<std::size_t>(r);
  }
  ::close(fd);
  data.resize(got);
  return data;
}

SimState decode_state(const std::string& path, std::string_view data) {
  // The prefix is checked field by field so each kind of wrong file gets its own message.
  const std::string_view magic(kMagic.data(), kMagic.size());
  if (data.size() < magic.size()) {
    if (magic.starts_with(data)) {
      throw file_error(path, "truncated: expected at least " + std::to_string(kHeaderBytes) +
                                 " bytes, found " + std::to_string(data.size()));
    }
    throw file_error(path, "not a thaw state file (bad magic)");
  }
  if (data.substr(0, magic.size()) != magic) throw file_error(path, "not a thaw state file (bad magic)");
  if (data.size() < kPrefixBytes) {
    throw file_error(path, "truncated: expected at least " + std::to_string(kHeaderBytes) + " bytes, found " +
                               std::to_string(data.size()));
  }
  const std::uint32_t version = load_u32(data, 8);
  if (version != kStateFileVersion) {
    throw file_error(path, "unsupported format version " + std::to_string(version) +
                               " (this build reads version " + std::to_string(kStateFileVersion) + " only)");
  }
  const std::uint32_t mark = load_u32(data, 12);
  if (mark != kByteOrderMark) {
    throw file_error(path, "bad byte-order marker " + hex(mark) + " (file is corrupt)");
  }
  if (data.size() < kHeaderBytes) {
    throw file_error(path, "truncated: expected at least " + std::to_string(kHeaderBytes) + " bytes, found " +
                               std::to_string(data.size()));
  }

  // The header has its own sum so its file size can be trusted to tell truncation from corruption.
  const std::uint64_t header_sum = load_u64(data, kHeaderBytes - 8);
  const std::uint64_t header_computed = fnv1a64(data.substr(0, kHeaderBytes - 8));
  if (header_sum != header_computed) {
    throw file_error(path, "header checksum mismatch (file is corrupt): stored " + hex(header_sum) +
                               ", computed " + hex(header_computed));
  }
  ByteReader r(path, data, kPrefixBytes);
  const std::uint64_t file_size = r.u64();
  if (file_size != data.size()) {
    throw file_error(path, std::string(data.size() < file_size ? "truncated" : "trailing bytes") +
                               ": expected " + std::to_string(file_size) + " bytes, found " +
                               std::to_string(data.size()));
  }
  const std::uint64_t sum = load_u64(data, data.size() - kTrailerBytes);
  const std::uint64_t computed = fnv1a64(data.substr(0, data.size() - kTrailerBytes));
  if (sum != computed) {
    throw file_error(
        path, "checksum mismatch (file is corrupt): stored " + hex(sum) + ", computed " + hex(computed));
  }

  SimState s;
  const std::uint64_t n = r.u64();
  s.step = r.u64();
  r.f64(s.time);
  r.f64(s.dt);
  s.clamped = r.u64();
  const std::uint64_t scene_bytes = r.u64();
  const std::uint32_t section_count = r.u32();
  r.u32();  // flags: none defined in version 1
  r.u64();  // header sum, verified above
  s.scene_json = std::string(r.bytes(scene_bytes, "the scene JSON"));

  // Sections end before the trailer; reading past it would treat the checksum as data.
  ByteReader sections(path, data.substr(0, data.size() - kTrailerBytes), r.pos());
  if (n > sections.remaining()) {
    throw file_error(path, "array sizes inconsistent: header says " + std::to_string(n) +
                               " particles, more than the file can hold");
  }
  s.particles.resize(static_cast<std::size_t>(n));
  std::vector<std::string> seen;
  for (std::uint32_t k = 0; k < section_count; ++k) {
    const std::uint32_t name_length = sections.u32();
    if (name_length > kMaxSectionName) {
      throw file_error(path, "malformed: section " + std::to_string(k) + " has a name of " +
                                 std::to_string(name_length) + " bytes");
    }
    const std::string name(sections.bytes(name_length, "section name"));
    const std::uint32_t flags = sections.u32();
    const std::uint32_t element_size = sections.u32();
    const std::uint64_t count = sections.u64();
    if (element_size != 0 && count > sections.remaining() / element_size) {
      throw file_error(path, "malformed: section '" + name + "' declares " + std::to_string(count) +
                                 " elements of " + std::to_string(element_size) +
                                 " bytes, more than the file holds");
    }
    const std::string_view payload = sections.bytes(count * element_size, "section '" + name + "'");
    if (std::find(seen.begin(), seen.end(), name) != seen.end()) {
      throw file_error(path, "malformed: section '" + name + "' appears twice");
    }
    seen.push_back(name);

    bool known = false;
    for_each_global(s, [&](const char* global_name, std::vector<double>& values) {
      if (name != global_name || !(flags & kSectionGlobal)) return;
      if (element_size != 8)
        throw file_error(path, "section '" + name + "' has elements of " + std::to_string(element_size) +
                                   " bytes, expected 8");
      known = true;
      values.resize(static_cast<std::size_t>(count));
      copy_little_endian(reinterpret_cast<char*>(values.data()), payload.data(), payload.size(), 8);
    });
    auto read_array = [&](const char* array_name, auto& array) {
      using Element = std::remove_cvref_t<decltype(array[0])>;
      if (name != array_name) return;
      known = true;
      if (element_size != sizeof(Element)) {
        throw file_error(path, "section '" + name + "' has elements of " + std::to_string(element_size) +
                                   " bytes, expected " + std::to_string(sizeof(Element)));
      }
      if (count != n) {
        throw file_error(path, "array sizes inconsistent: section '" + name + "' has " +
                                   std::to_string(count) + " elements, header says " + std::to_string(n) +
                                   " particles");
      }
      array.resize(static_cast<std::size_t>(n));
      copy_little_endian(reinterpret_cast<char*>(array.data()), payload.data(), payload.size(),
                         word_size<Element>());
    };
    for_each_array(s.particles, read_array);
    for_each_optional_array(s, read_array);
    // A declared field's column: its spec from the flags (or, in older files, from its name).
    std::optional<FieldSpec> spec;
    const auto type = static_cast<FieldType>((flags >> 8) & 0xff);
    if (!known && !(flags & kSectionGlobal)) {
      if (type == FieldType::Float32 || type == FieldType::UInt32 || type == FieldType::UInt8)
        spec = FieldSpec{name, type, int((flags >> 16) & 0xff), true, (flags & kSectionExported) != 0};
      else if (type == FieldType(0))
        spec = legacy_field(name);
    }
    if (spec) {
      if (spec->width != 1 && spec->width != 2 && spec->width != 4)
        throw file_error(path, "section '" + name + "' declares a width of " + std::to_string(spec->width));
      if (element_size != spec->bytes())
        throw file_error(path, "section '" + name + "' has elements of " + std::to_string(element_size) +
                                   " bytes, expected " + std::to_string(spec->bytes()));
      if (count != n)
        throw file_error(path, "array sizes inconsistent: section '" + name + "' has " +
                                   std::to_string(count) + " elements, header says " + std::to_string(n) +
                                   " particles");
      HostColumn c{*spec, std::vector<std::uint8_t>(payload.size())};
      copy_little_endian(reinterpret_cast<char*>(c.bytes.data()), payload.data(), payload.size(),
                         scalar_bytes(spec->type));
      s.particles.columns.push_back(std::move(c));
      known = true;
    }
    if (!known && (flags & kSectionRequired)) {
      throw file_error(path, "unknown required section '" + name +
                                 "' (written by a newer thaw; this build cannot resume it)");
    }
  }
  if (sections.remaining() != 0) {
    throw file_error(path, "malformed: " + std::to_string(sections.remaining()) +
                               " unexplained bytes after " + std::to_string(section_count) + " sections");
  }
  for_each_array(s.particles, [&](const char* array_name, const auto&) {
    if (std::find(seen.begin(), seen.end(), array_name) == seen.end()) {
      throw file_error(path, std::string("missing required section '") + array_name + "'");
    }
  });
  for (std::size_t i = 0; i < n; ++i) {
    if (s.particles.phase[i] >= kPhaseCount) {
      throw file_error(path, "particle " + std::to_string(i) + " has phase " +
                                 std::to_string(s.particles.phase[i]) + " (valid: 0.." +
                                 std::to_string(kPhaseCount - 1) + ")");
    }
  }
  return s;
}

// Closes fd (if open), removes the temp file (if any) and throws; `err` is errno captured at the failure,
// before anything else could overwrite it.
[[noreturn]] void fail_write(const std::string& path, const std::string& tmp, int fd, int err,
                             const std::string& step) {
  if (fd >= 0) ::close(fd);
  if (!tmp.empty()) ::unlink(tmp.c_str());
  throw Error("cannot write '" + path + "': " + step + ": " + errno_text(err));
}

}  // namespace

std::uint64_t fnv1a64(std::string_view bytes, std::uint64_t hash) {
  for (char c : bytes) {
    hash ^= static_cast<unsigned char>(c);
    hash *= 0x100000001b3ull;
  }
  return hash;
}

void write_file_atomically(const std::string& path, std::string_view bytes, Durability durability) {
  // Same directory as the target: rename is atomic only within one file system.
  const std::string tmp = path + ".tmp." + std::to_string(::getpid());
  // O_TRUNC, not O_EXCL: a leftover with our pid is from a dead process that had it before us.
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) fail_write(path, "", -1, errno, "cannot create temp file '" + tmp + "'");
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t w = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (w < 0 && errno == EINTR) continue;
    if (w < 0) fail_write(path, tmp, fd, errno, "write to '" + tmp + "' failed");
    done += static_cast<std::size_t>(w);
  }
  // Without this fsync a power cut after the rename can leave an empty file under the final name.
  if (durability == Durability::Durable && ::fsync(fd) != 0) fail_write(path, tmp, fd, errno, "fsync failed");
  if (::close(fd) != 0) fail_write(path, tmp, -1, errno, "close failed");
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    fail_write(path, tmp, -1, errno, "rename from '" + tmp + "' failed");
  }
  if (durability == Durability::Durable) {
    // The rename itself is only durable once the directory entry is on disk.
    std::string dir = std::filesystem::path(path).parent_path().string();
    if (dir.empty()) dir = ".";
    const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dfd < 0) fail_write(path, "", -1, errno, "cannot open directory '" + dir + "' to fsync it");
    if (::fsync(dfd) != 0) fail_write(path, "", dfd, errno, "fsync of directory '" + dir + "' failed");
    ::close(dfd);
  }
}

void write_state_file(const std::string& path, const SimState& state) {
  if (auto problem = inconsistent_sizes(state.particles)) {
    throw Error("cannot write state file '" + path + "': " + *problem);
  }
  write_file_atomically(path, encode_state(state), Durability::Durable);
}

SimState read_state_file(const std::string& path) { return decode_state(path, read_whole_file(path)); }

namespace {

// "section 'NAME', particle I (id N): ", how a refusal names a particle.
std::string particle_in(const HostParticles& p, const std::string& section, std::size_t i) {
  return "section '" + section + "', particle " + std::to_string(i) +
         (i < p.id.size() ? " (id " + std::to_string(p.id[i]) + ")" : "") + ": ";
}

// A state's values against what the scene's physics allows, once each is known to be finite: temperatures
// above absolute zero, each substance field naming a substance the scene declares (of its kind) with amounts
// neither negative nor more than the particle's own mass, melt shifts within the law's range, and the
// books (energy and substances) closing against the particles. Checksums prove a file is what was written,
// not that a kernel can run it (StatePhysics in tests/sim/state_file_test.cpp has what got through before).
void check_state_physics(const SimState& s, const Scene& scene,
                         const std::function<void(const std::string&)>& refuse) {
  const HostParticles& p = s.particles;
  const auto num = format_number;
  const auto where = [&p](const std::string& section, std::size_t i) { return particle_in(p, section, i); };
  const double rest = derive_constants(scene).rest_density;
  const std::vector<thermal::MaterialThermal> table = material_thermal_table(scene, rest);
  const auto physical_mass = [&](std::size_t i) {
    return double(p.position[i][3]) * table[p.material[i]].thermal_mass_scale;
  };

  // Temperatures: a corrupted enthalpy otherwise ran until a force blew up, and the message blamed the time
  // step.
  constexpr double kHottest = 1e4;
  double enthalpy = 0, enthalpy_scale = 0;
  for (std::size_t i = 0; i < p.size() && !p.enthalpy.empty(); ++i) {
    const double h = double(p.enthalpy[i][0]) + double(p.enthalpy[i][1]);
    const double t = temperature_at(table[p.material[i]], h);
    if (!(t >= -273.15) || t > kHottest)
      refuse(where("enthalpy", i) + num(h) + " J/kg is a temperature of " + num(t) +
             " °C, outside -273.15 to " + num(kHottest) + " °C");
    enthalpy += physical_mass(i) * h;
    enthalpy_scale += physical_mass(i) * std::abs(h);
  }

  // Substance fields: each names one of the scene's substances, of the kind the field is for.
  std::string declared;
  for (const Substance& sub : scene.substances) declared += (declared.empty() ? "" : ", ") + sub.name;
  std::vector<double> total(scene.substances.size(), 0.0);
  const struct {
    const char* prefix;
    const char* what;
    bool (*fits)(const Substance&);
  } kinds[] = {
      {kSubstancePrefix, "dissolved substance", [](const Substance&) { return true; }},
      {kAdsorbedPrefix, "surface-active substance", [](const Substance& x) { return x.surface_active(); }},
      {kDepositedPrefix, "coating", [](const Substance& x) { return x.coating(); }}};
  for (const HostColumn& c : p.columns) {
    const std::string& name = c.spec.name;
    if (name == kMeltShiftField) {
      const float* d = c.as<float>();
      for (std::size_t i = 0; i < c.size(); ++i)
        if (!(d[i] >= 0) || d[i] > kMaxMeltingPointDrop * (1 + 1e-6))
          refuse(where(name, i) + num(d[i]) + " K is not a melt shift from 0 to " +
                 num(kMaxMeltingPointDrop) + " K");
      continue;
    }
    for (const auto& kind : kinds) {
      if (name.rfind(kind.prefix, 0) != 0) continue;
      const std::string sub = name.substr(std::strlen(kind.prefix));
      std::size_t k = 0;
      while (k < scene.substances.size() && scene.substances[k].name != sub) ++k;
      if (k == scene.substances.size() || !kind.fits(scene.substances[k]))
        refuse("section '" + name + "': the scene declares no " + kind.what + " '" + sub +
               "' (its substances: " + (declared.empty() ? "none" : declared) + ")");
      if (c.spec.type != FieldType::Float32 || c.spec.width != 2 || c.size() != p.size())
        refuse("section '" + name + "': not one pair of floats per particle");
      const Float2* a = c.as<Float2>();
      for (std::size_t i = 0; i < p.size(); ++i) {
        const double amount = double(a[i][0]) + double(a[i][1]), mass = physical_mass(i);
        if (amount < -1e-6 * mass) refuse(where(name, i) + num(amount) + " kg of " + sub + " is negative");
        if (amount > mass)
          refuse(where(name, i) + num(amount) + " kg of " + sub + " is more than the particle's own mass, " +
                 num(mass) + " kg");
        total[k] += amount;
      }
    }
  }
  if (!s.substances.empty()) {
    SubstanceBooks b;
    try {
      b = SubstanceBooks::from_vector(s.substances, scene.substances.size());
    } catch (const Error& e) {
      refuse(std::string("section 'substances': ") + e.what());
    }
    for (std::size_t k = 0; k < scene.substances.size(); ++k) {
      const std::string& sub = scene.substances[k].name;
      for (const auto& [value, what] :
           {std::pair{b.initial[k], "at the start"}, std::pair{b.outflow[k], "gone out"},
            std::pair{b.inflow[k], "poured in"}})
        if (value < 0)
          refuse("section 'substances': " + num(value) + " kg of " + sub + " " + what + " is negative");
      // The stage conserves to round-off (1e-14 of the totals, docs/SUBSTANCES.md).
      const double closure = b.closure(k, total[k]), scale = b.initial[k] + b.inflow[k];
      if (std::abs(closure) > 1e-6 * scale + 1e-30)
        refuse("section 'substances': " + sub + "'s books do not close against its particles: " +
               num(total[k]) + " kg held + " + num(b.outflow[k]) + " gone out, against " + num(b.initial[k]) +
               " at the start + " + num(b.inflow[k]) + " poured in");
    }
  }
  if (!s.energy_budget.empty() && !p.enthalpy.empty()) {
    EnergyBudget b;
    try {
      b = EnergyBudget::from_vector(s.energy_budget);
    } catch (const Error& e) {
      refuse(std::string("section 'energy_budget': ") + e.what());
    }
    // Runs close to 1e-9 of their heat or less (docs/VALIDATION-RESULTS.md); a thousandth is no round-off.
    const double gross = std::abs(b.ambient) + std::abs(b.lamps) + std::abs(b.dryers) + std::abs(b.walls) +
                         std::abs(b.held) + std::abs(b.outflow) + std::abs(b.inflow);
    const double closure = enthalpy - b.initial - b.heat_in();
    if (std::abs(closure) > 1e-3 * std::max({enthalpy_scale, gross, 1e-300}))
      refuse("section 'energy_budget': the books do not close against the particles' enthalpy: " +
             num(enthalpy) + " J held, against " + num(b.initial) + " J at the start and " +
             num(b.heat_in()) + " J in since");
  }
}

}  // namespace

void check_state(const SimState& s, const Scene& scene, const std::string& origin) {
  const auto refuse = [&origin](const std::string& what) { throw Error(origin + ": " + what); };
  const auto num = format_number;
  if (!std::isfinite(s.time) || s.time < 0) refuse("time " + num(s.time) + " s is not a finite time >= 0");
  if (!std::isfinite(s.dt) || s.dt < 0) refuse("dt " + num(s.dt) + " s is not a finite time step >= 0");

  Eigen::AlignedBox3d region(scene.domain.min, scene.domain.max);
  for (const IceBlock& b : scene.ice) region.extend(b.box.min).extend(b.box.max);
  for (const Solid& b : scene.solids)
    if (!b.plane) region.extend(b.box.min).extend(b.box.max);
  const double margin = (wall_layer_count(scene) + 2) * scene.spacing;
  region.min().array() -= margin;
  region.max().array() += margin;

  const HostParticles& p = s.particles;
  const auto where = [&p](const std::string& section, std::size_t i) { return particle_in(p, section, i); };
  const auto finite4 = [](const Float4& v, int n) {
    for (int k = 0; k < n; ++k)
      if (!std::isfinite(v[std::size_t(k)])) return false;
    return true;
  };
  const auto vec = [&num](const auto& v) {
    return "(" + num(double(v[0])) + ", " + num(double(v[1])) + ", " + num(double(v[2])) + ")";
  };
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Float4& x = p.position[i];
    if (!finite4(x, 3)) refuse(where("position", i) + vec(x) + " is not finite");
    if (!region.contains(Eigen::Vector3d(x[0], x[1], x[2])))
      refuse(where("position", i) + vec(x) +
             " m lies outside the region this scene's particles can occupy, " + "from " + vec(region.min()) +
             " to " + vec(region.max()) + " m");
    if (!std::isfinite(x[3]) || !(x[3] > 0))
      refuse(where("position", i) + "mass " + num(x[3]) + " kg is not finite and positive");
    if (!finite4(p.velocity[i], 3)) refuse(where("velocity", i) + vec(p.velocity[i]) + " is not finite");
    if (!std::isfinite(p.density[i]) || p.density[i] < 0)
      refuse(where("density", i) + num(p.density[i]) + " kg/m^3 is not finite and >= 0");
    if (p.phase[i] >= kPhaseCount)
      refuse(where("phase", i) + std::to_string(p.phase[i]) + " is not a phase (0.." +
             std::to_string(kPhaseCount - 1) + ")");
    if (p.material[i] >= scene.materials.size())
      refuse(where("material", i) + "material " + std::to_string(p.material[i]) +
             " does not exist; the scene has " + std::to_string(scene.materials.size()));
    if (!std::isfinite(p.enthalpy[i][0]) || !std::isfinite(p.enthalpy[i][1]))
      refuse(where("enthalpy", i) + num(p.enthalpy[i][0]) + " + " + num(p.enthalpy[i][1]) +
             " J/kg is not finite");
    if (i < p.anchored.size() && p.anchored[i] > 1)
      refuse(where("anchored", i) + std::to_string(p.anchored[i]) + " is neither 0 nor 1");
  }
  for (const HostColumn& c : p.columns) {
    if (c.spec.type != FieldType::Float32) continue;
    const float* v = c.as<float>();
    for (std::size_t k = 0; k < c.bytes.size() / 4; ++k)
      if (!std::isfinite(v[k]))
        refuse(where(c.spec.name.c_str(), k / std::size_t(c.spec.width)) + "not finite");
  }
  const auto all_finite = [&](const std::vector<double>& v, const char* section) {
    for (std::size_t k = 0; k < v.size(); ++k)
      if (!std::isfinite(v[k]))
        refuse(std::string("section '") + section + "', entry " + std::to_string(k) + ": not finite");
  };
  all_finite(s.energy_budget, "energy_budget");
  all_finite(s.rigid_bodies, "rigid_bodies");
  all_finite(s.rigid_labelling, "rigid_labelling");
  all_finite(s.outflow, "outflow");
  all_finite(s.inflow, "inflow");
  all_finite(s.substances, "substances");
  check_state_physics(s, scene, refuse);
}

}  // namespace thaw
