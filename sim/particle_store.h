#pragma once
// The particles' device buffers, one per declared field (sim/particle_fields.h), and what follows from
// the declarations: allocation, the neighbour sort's reorder (one generated kernel that gathers every
// field in one pass), upload from and download to HostParticles. Stages add their fields before
// allocate(); the store knows nothing of what a field means.
#include <CL/opencl.hpp>
#include <cstddef>
#include <string>
#include <vector>

#include "sim/cl_runtime.h"
#include "sim/particle_fields.h"
#include "sim/particles.h"

namespace thaw {

class ParticleStore {
 public:
  using Field = std::size_t;  // a handle from add()

  explicit ParticleStore(ClRuntime& cl) : cl_(cl) {}

  // Declares a field; before allocate(). The name must be a C identifier and not declared before
  // (Error otherwise): it names the kernel's arguments.
  Field add(FieldSpec spec);

  // Allocates every field for a capacity of n particles, all in use, (and a spare of each for the reorder)
  // and builds the reorder. Every store has "position" and "velocity" (float4): the reorder also writes their
  // structure-of-arrays copy that the neighbour loops read.
  void allocate(std::size_t n);

  cl::Buffer& operator[](Field f) { return buffers_[f]; }
  const cl::Buffer& operator[](Field f) const { return buffers_[f]; }
  const std::vector<FieldSpec>& specs() const { return specs_; }
  bool has(const std::string& name) const;
  std::size_t size() const { return n_; }  // the particles in use
  std::size_t capacity() const { return capacity_; }
  // Uses the first n particles of the capacity (particles past n are gone: water that left).
  void resize(std::size_t n);
  // Writes p's particles after the n in use, as upload() does, and uses them too (an emitter's); Error
  // when they do not fit in the capacity.
  void append(const HostParticles& p);
  // Forgets every field and buffer, to be declared and allocated again (the solver growing its capacity).
  void clear();
  // Bytes of device memory the fields take, spares included.
  std::size_t device_bytes() const;

  // Gathers every field into the sort's order: field[i] = field[order[i]] for i < n, and writes
  // soa = x, y, z, m, vx, vy, vz blocks of `stride` floats (sim/kernels/grid_common.h).
  void reorder(const cl::Buffer& order, const cl::Buffer& soa, cl_uint stride);

  // Writes each field from p: a core member of HostParticles (position, velocity, density, phase,
  // material, id, enthalpy) or a column of the same name. A field p does not hold (or holds with another
  // element size or count) is filled with its spec's `fill`.
  void upload(const HostParticles& p);
  // Reads every field into p (resized to size()): core members, other fields as columns.
  void download(HostParticles& p) const;

  // The generated OpenCL source of the reorder (for tests and the curious).
  std::string reorder_source() const;

 private:
  void write(const HostParticles& p, std::size_t first, std::size_t count);  // p's particles from `first`

  ClRuntime& cl_;
  std::vector<FieldSpec> specs_;
  std::vector<cl::Buffer> buffers_, spares_;
  std::size_t n_ = 0, capacity_ = 0;
  cl::Kernel k_reorder_;
};

}  // namespace thaw
