#pragma once
// State files: everything a run needs to resume, in a versioned, checksummed binary file that is
// replaced atomically, so a resumed run continues bitwise identically and a crash mid-write never
// leaves a half-written state behind.
//
// Layout, version 1 (all integers little-endian; floats as the exact bytes of their IEEE-754 bits):
//   magic          8 bytes  "\x89THAW\r\n\x1a"
//   version        u32      kStateFileVersion
//   byte order     u32      0x01020304
//   file size      u64      bytes in the whole file, trailer included
//   particles      u64      particle count; every array section holds this many elements
//   step           u64
//   time           f64
//   dt             f64
//   clamped        u64
//   scene bytes    u64      length of the scene JSON that follows the header
//   sections       u32      number of array sections
//   flags          u32      0 in version 1
//   header sum     u64      FNV-1a-64 of every byte above
//   scene JSON     bytes
//   sections       each: name length u32, name, flags u32 (bit 0: required; bit 1: global, i.e. a
//                  record of the run whose count is its own, not the particle count; for a declared
//                  field, bit 2: exported, bits 8-15: FieldType, bits 16-23: width), element size u32,
//                  count u64, count * element size bytes. Per particle: position, velocity, density,
//                  phase, material, id, enthalpy (two floats: hi, lo); where present, anchored (u8:
//                  particles of fixed ice objects); then every field a stage declared
//                  (HostParticles::columns, e.g. body (u32) and body_offset (four floats) of runs with
//                  free ice; files written before the type bits existed hold those two untyped).
//                  Global: energy_budget (doubles), rigid_bodies and rigid_labelling (doubles, only in
//                  runs with free ice), outflow (runs where water left through an open side), inflow
//                  (runs with emitters), substances (runs with substances).
//   checksum       u64      FNV-1a-64 of every byte before it
// Arrays are named sections so later versions can add per-particle fields (temperature, enthalpy,
// body id) without breaking readers: a reader skips unknown optional sections and refuses unknown
// required ones, since ignoring those would resume a different simulation.
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "sim/particles.h"

namespace thaw {

inline constexpr std::uint32_t kStateFileVersion = 1;

struct SimState {
  HostParticles particles;
  std::uint64_t step = 0;     // steps taken
  double time = 0.0;          // simulated time [s]
  double dt = 0.0;            // last time step [s]
  std::uint64_t clamped = 0;  // particles clamped back into the domain so far
  std::string scene_json;     // the resolved scene document the run used
  // The run's energy account [J] (sim/solver.h, EnergyBudget::to_vector). Stored as
  // the section "energy_budget" (flags: required, global), whose count is its own.
  std::vector<double> energy_budget;
  // Rigid ice (sim/rigid_ice.h), in runs with free ice only: the bodies with their labelling schedule
  // (global section "rigid_bodies"); each particle's body and offset are fields (particles.columns).
  std::vector<double> rigid_bodies;
  // The last labelling's record (global section "rigid_labelling"): its sweeps, then each body's shape,
  // its particle count and their body-frame offsets, which keep it inside the domain. Files written
  // before the section existed resume with 0 sweeps, and before the shapes, with each body's particles.
  std::vector<double> rigid_labelling;
  // What left through open sides (OutflowBooks::to_vector, global section "outflow"); empty: nothing.
  std::vector<double> outflow;
  // Emitters (EmitterStage::save, global section "inflow"): what came in, the next particle id, the
  // capacity and each emitter's pending length; empty in runs without emitters.
  std::vector<double> inflow;
  // Substances (SubstanceBooks::to_vector, global section "substances"): each one's total at the start,
  // then what left through open sides; empty in runs without substances.
  std::vector<double> substances;
};

// The bytes a state file of `state` holds.
std::string encode_state(const SimState& state);

// Each section of `state` with the bytes it holds in memory, in the file's order, after a "header" section of
// the particle count, step, time, dt and clamped count: to tell which part of two states differs.
void for_each_state_section(const SimState& state,
                            const std::function<void(const std::string&, std::string_view)>& visit);

// Writes `state` to `path` atomically and durably; throws thaw::Error naming the path and the reason.
void write_state_file(const std::string& path, const SimState& state);

// Reads and verifies a state file (magic, version, byte order, sizes, both checksums, every section);
// every failure is a thaw::Error naming the file and what was wrong.
SimState read_state_file(const std::string& path);

// Checks what a state file holds against the scene it will run: the time finite and not negative, the
// time step finite and not negative, and for every particle a finite position inside the region the
// scene's particles can occupy (its domain, solids and ice, grown by the wall layers and two spacings),
// a finite positive mass, a finite velocity, density and enthalpy, a known phase, a material the scene
// has, and the rigid ice records finite. A checksum proves the file is what was written, not that it
// is sane: a hand-made or buggy file must be refused here, before a kernel meets it (positions at 1e9
// overflowed the neighbour grid's cell count and crashed inside the OpenCL driver). Throws Error
// naming `origin` (the file), the section and the particle.
struct Scene;
void check_state(const SimState& state, const Scene& scene, const std::string& origin);

// FNV-1a, 64 bit. Any single changed byte always changes the sum: each step is a bijection of the
// running hash for a fixed input byte.
std::uint64_t fnv1a64(std::string_view bytes, std::uint64_t hash = 0xcbf29ce484222325ull);

// How hard write_file_atomically works to survive a power cut, not just a crash of this process.
enum class Durability {
  Visible,  // temp + rename: readers see the old file or the whole new one (exports: cheap)
  Durable,  // also fsync the file before the rename and the directory after (state files)
};

// Writes `bytes` to "PATH.tmp.<pid>" beside `path` and renames it over `path`. On failure the temp
// file is removed, `path` keeps its previous content, and a thaw::Error names the path and errno text.
// Shared by the particle exporter, whose frames must never be seen half-written either.
void write_file_atomically(const std::string& path, std::string_view bytes, Durability durability);

}  // namespace thaw
