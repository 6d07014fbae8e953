#include "sim/rigid_ice.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <limits>
#include <map>

#include "sim/cl_launch.h"
#include "sim/error.h"
#include "sim/stage.h"

namespace thaw {
namespace {

// Must match `Body` in sim/kernels/rigid.cl.
struct ClBody {
  cl_float4 centre;  // w: 1 free, 0 fixed
  cl_float4 r0, r1, r2;
  cl_float4 velocity;
  cl_float4 omega;
};
static_assert(sizeof(ClBody) == 96, "ClBody must match the OpenCL struct's layout");

// Must match `Contact` in sim/kernels/rigid.cl.
struct ClContact {
  cl_float stiffness, damping, friction, distance;
};

cl_float4 f4(const Eigen::Vector3d& v, float w = 0.f) {
  return {{float(v.x()), float(v.y()), float(v.z()), w}};
}

// Two ice particles belong to one body when closer than this many spacings: lattice face (1) and edge
// (1.41) neighbours, not corner ones (1.73), so a body held by a single corner contact falls apart.
constexpr double kConnectSpacings = 1.5;

// A body as doubles for state files: mass, moments, position, velocity, orientation (w, x, y, z),
// angular momentum, fixed.
constexpr std::size_t kBodyDoubles = 18;

std::vector<double> to_vector(const RigidBody& r) {
  const Eigen::Quaterniond& q = r.orientation;
  return {r.mass,
          r.moments.x(),
          r.moments.y(),
          r.moments.z(),
          r.position.x(),
          r.position.y(),
          r.position.z(),
          r.velocity.x(),
          r.velocity.y(),
          r.velocity.z(),
          q.w(),
          q.x(),
          q.y(),
          q.z(),
          r.angular_momentum.x(),
          r.angular_momentum.y(),
          r.angular_momentum.z(),
          r.fixed ? 1.0 : 0.0};
}

RigidBody body_from_vector(const std::vector<double>& v) {
  if (v.size() != kBodyDoubles)
    throw Error("rigid ice state: a body has " + std::to_string(v.size()) + " numbers, expected " +
                std::to_string(kBodyDoubles));
  RigidBody r;
  r.mass = v[0];
  r.moments = {v[1], v[2], v[3]};
  r.position = {v[4], v[5], v[6]};
  r.velocity = {v[7], v[8], v[9]};
  r.orientation = Eigen::Quaterniond(v[10], v[11], v[12], v[13]);
  r.angular_momentum = {v[14], v[15], v[16]};
  r.fixed = v[17] != 0;
  return r;
}

}  // namespace

RigidIce::RigidIce(ClRuntime& cl, ParticleStore& store, const std::string& build_options,
                   std::size_t capacity, Settings settings, std::vector<std::uint8_t> anchored_by_id,
                   std::vector<float> mass_scale)
    : cl_(cl),
      store_(store),
      settings_(std::move(settings)),
      anchored_by_id_(std::move(anchored_by_id)),
      mass_scale_(std::move(mass_scale)) {
  const auto program =
      cl.build(neighbour_program({"fluid_params.h", "dfsph_columns.h", "tension_params.h", "rigid.cl"}),
               build_options);
  k_forces_ = cl::Kernel(program, "rigid_forces");
  k_place_ = cl::Kernel(program, "rigid_place");
  labeller_ = std::make_unique<IceLabeller>(cl, settings_.grid_reach);
  reducer_ = std::make_unique<BodyReducer>(cl, mass_scale_);
  auto& ctx = cl.context();
  const std::size_t m = std::max<std::size_t>(capacity, 1);
  // Each particle's body (kNoBody: none) and its offset in the body's frame, sorted with the particles.
  body_ = store.add({"body", FieldType::UInt32, 1, true, true, kNoBody});
  offset_ = store.add({"body_offset", FieldType::Float32, 4});
  force_ = cl::Buffer(ctx, CL_MEM_READ_WRITE, m * 16);
  label_ = cl::Buffer(ctx, CL_MEM_READ_WRITE, m * 4);
  bodies_capacity_ = 0;
  upload_bodies();
}

RigidIce::~RigidIce() = default;

void RigidIce::upload_bodies() {
  std::vector<ClBody> out(std::max<std::size_t>(bodies_.size(), 1));
  std::vector<cl_float4> refs(out.size());
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    const RigidBody& r = bodies_[b].body;
    const Eigen::Matrix3d R = r.orientation.toRotationMatrix();
    out[b].centre = f4(r.position, r.fixed ? 0.f : 1.f);
    out[b].r0 = f4(R.row(0).transpose());
    out[b].r1 = f4(R.row(1).transpose());
    out[b].r2 = f4(R.row(2).transpose());
    out[b].velocity = f4(r.fixed ? Eigen::Vector3d::Zero() : r.velocity);
    out[b].omega = f4(r.fixed ? Eigen::Vector3d::Zero() : r.angular_velocity());
    refs[b] = f4(r.position);
  }
  if (out.size() > bodies_capacity_) {
    bodies_capacity_ = out.size() * 2;
    bodies_dev_ = cl::Buffer(cl_.context(), CL_MEM_READ_ONLY, bodies_capacity_ * sizeof(ClBody));
    refs_ = cl::Buffer(cl_.context(), CL_MEM_READ_ONLY, bodies_capacity_ * 16);
  }
  cl_.queue().enqueueWriteBuffer(bodies_dev_, CL_TRUE, 0, out.size() * sizeof(ClBody), out.data());
  cl_.queue().enqueueWriteBuffer(refs_, CL_TRUE, 0, refs.size() * 16, refs.data());
}

void RigidIce::relabel_if_due(const ParticleBuffers& p, std::uint64_t step, bool force) {
  const bool due = force || !labelled_ ||
                   (phase_changed_ && step >= labelled_step_ + std::uint64_t(settings_.relabel_interval));
  if (!due || p.n == 0) return;
  const std::size_t n = p.n;
  // Grouped by the bodies of the last labelling: melting splits bodies, touching never joins them (ice
  // that froze since, in no body yet, joins what it touches).
  const SortedIceParticles sorted{
      p.position,   p.phase,
      p.id,         p.cell_start,
      p.n,          static_cast<std::uint32_t>(std::max<std::size_t>({anchored_by_id_.size(), n, p.ids})),
      store_[body_]};
  last_iterations_ = static_cast<int>(
      labeller_->label(sorted, p.grid, static_cast<float>(kConnectSpacings * settings_.spacing), label_));
  // The bodies follow from the labels on the host: this runs only when ice changed phase.
  auto& q = cl_.queue();
  std::vector<std::uint32_t> label(n), id(n);
  std::vector<Float4> x(n), v(n);
  std::vector<std::uint8_t> material(n);
  q.enqueueReadBuffer(label_, CL_FALSE, 0, n * 4, label.data());
  q.enqueueReadBuffer(p.id, CL_FALSE, 0, n * 4, id.data());
  q.enqueueReadBuffer(p.position, CL_FALSE, 0, n * 16, x.data());
  q.enqueueReadBuffer(p.velocity, CL_FALSE, 0, n * 16, v.data());
  q.enqueueReadBuffer(p.material, CL_TRUE, 0, n, material.data());

  std::map<std::uint32_t, std::vector<std::uint32_t>> members;  // ascending labels: deterministic order
  for (std::uint32_t i = 0; i < n; ++i)
    if (label[i] != kNoBody) members[label[i]].push_back(i);

  std::vector<IceBody> bodies;
  bodies.reserve(members.size());
  std::vector<std::vector<Eigen::Vector3f>> shapes;
  shapes.reserve(members.size());
  std::vector<std::uint32_t> body(n, kNoBody);
  std::vector<Float4> offset(n, Float4{0.f, 0.f, 0.f, 0.f});
  for (const auto& [lab, idx] : members) {
    std::vector<Eigen::Vector3d> xs;
    std::vector<double> ms;
    xs.reserve(idx.size());
    ms.reserve(idx.size());
    bool fixed = false;
    for (std::uint32_t i : idx) {
      xs.emplace_back(x[i][0], x[i][1], x[i][2]);
      ms.push_back(double(x[i][3]) * double(mass_scale_[material[i]]));
      if (id[i] < anchored_by_id_.size() && anchored_by_id_[id[i]]) fixed = true;
    }
    const MassProperties mp = mass_properties(xs, ms, settings_.spacing);
    IceBody ib;
    ib.label = lab;
    ib.particles = idx.size();
    for (const Eigen::Vector3d& o : mp.offsets) ib.radius = std::max(ib.radius, o.norm());
    Eigen::Vector3d velocity = Eigen::Vector3d::Zero(), omega = Eigen::Vector3d::Zero();
    if (!fixed) {
      // The new body carries on the momentum and angular momentum its particles had (the motion of the
      // body or bodies they came from): V = P / M, and omega from L about the centre through the
      // point-mass inertia (the particles' own cube terms do not appear in sum m r x v).
      Eigen::Vector3d P = Eigen::Vector3d::Zero(), L = Eigen::Vector3d::Zero();
      for (std::size_t k = 0; k < idx.size(); ++k) {
        const Float4& vk = v[idx[k]];
        const Eigen::Vector3d vel(vk[0], vk[1], vk[2]);
        P += ms[k] * vel;
        L += ms[k] * (xs[k] - mp.centre).cross(vel);
      }
      velocity = P / mp.mass;
      const double cube = mp.mass * settings_.spacing * settings_.spacing / 6.0;
      const Eigen::Matrix3d point_inertia = mp.inertia - cube * Eigen::Matrix3d::Identity();
      omega = point_inertia.completeOrthogonalDecomposition().solve(L);
    }
    ib.body = rigid_body(mp, velocity, omega);
    ib.body.fixed = fixed;
    const std::uint32_t b = static_cast<std::uint32_t>(bodies.size());
    std::vector<Eigen::Vector3f> shape(idx.size());
    for (std::size_t k = 0; k < idx.size(); ++k) {
      body[idx[k]] = b;
      shape[k] = mp.offsets[k].cast<float>();
      offset[idx[k]] = Float4{shape[k].x(), shape[k].y(), shape[k].z(), 0.f};
    }
    bodies.push_back(std::move(ib));
    shapes.push_back(std::move(shape));
  }
  bodies_ = std::move(bodies);
  shapes_ = std::move(shapes);
  q.enqueueWriteBuffer(store_[body_], CL_FALSE, 0, n * 4, body.data());
  q.enqueueWriteBuffer(store_[offset_], CL_TRUE, 0, n * 16, offset.data());
  upload_bodies();
  labelled_ = true;
  labelled_step_ = step;
  phase_changed_ = false;
  ++labellings_;
}

void RigidIce::use_tension(const std::vector<float>& adhesion) {
  std::vector<float> table = adhesion;
  if (table.empty()) table.push_back(0.0f);
  adhesion_ = cl::Buffer(cl_.context(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, table.size() * sizeof(float),
                         table.data());
}

void RigidIce::compute_forces(const ParticleBuffers& p) {
  const ContactModel& c = settings_.contact;
  const ClContact contact{float(c.stiffness), float(c.damping), float(c.friction), float(c.distance)};
  const float h = static_cast<float>(settings_.smoothing);
  set_args(k_forces_, p.position, p.velocity, p.state, p.phase, store_[body_], bodies_dev_, p.cell_start,
           p.grid, static_cast<float>(settings_.support), 0.01f * h * h,
           static_cast<float>(settings_.visc_boundary), static_cast<float>(settings_.rest_density), contact,
           force_, p.n);
  if (flow_) {  // multiphase builds (rigid.cl): each fluid neighbour's rest volume and density
    k_forces_.setArg(15, p.material);
    k_forces_.setArg(16, *flow_);
    k_forces_.setArg(17, *columns_);
    k_forces_.setArg(18, columns_stride_);
  }
  if (adhesion_()) {  // after the multiphase arguments where there are any
    const cl_uint at = flow_ ? 19 : 15;
    k_forces_.setArg(at, p.material);
    k_forces_.setArg(at + 1, adhesion_);
  }
  launch(cl_.queue(), k_forces_, p.n);
}

double RigidIce::max_point_speed() const {
  double fastest = 0;
  for (const IceBody& b : bodies_) {
    if (b.body.fixed) continue;
    fastest = std::max(fastest, b.body.velocity.norm() + b.body.angular_velocity().norm() * b.radius);
  }
  return fastest;
}

void RigidIce::advance(const ParticleBuffers& p, double dt) {
  if (bodies_.empty()) return;
  const std::vector<BodySums> sums = reducer_->reduce({p.position, p.material, force_, store_[body_], p.n},
                                                      refs_, static_cast<std::uint32_t>(bodies_.size()));
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    RigidBody& r = bodies_[b].body;
    if (r.fixed || held_) continue;
    thaw::advance(r, sums[b].force + r.mass * settings_.gravity, sums[b].torque, dt);
    if (confine(b)) ++clamped_;
  }
  upload_bodies();
  set_args(k_place_, p.position, p.velocity, p.phase, store_[body_], store_[offset_], bodies_dev_, p.n);
  launch(cl_.queue(), k_place_, p.n);
}

bool RigidIce::confine(std::size_t b) {
  RigidBody& r = bodies_[b].body;
  // Most steps every body is further than its radius from every face: no need to visit its particles.
  const double reach = bodies_[b].radius * (1.0 + 1e-6);
  if ((r.position - settings_.domain_min).minCoeff() >= reach &&
      (settings_.domain_max - r.position).minCoeff() >= reach)
    return false;
  const Eigen::Matrix3d R = r.orientation.toRotationMatrix();
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Eigen::Vector3f& o : shapes_[b]) {
    const Eigen::Vector3d x = r.position + R * o.cast<double>();
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  bool moved = false;
  for (int a = 0; a < 3; ++a) {
    // A body wider than the domain cannot fit; it is kept off the lower face.
    if (hi[a] > settings_.domain_max[a]) {
      r.position[a] -= hi[a] - settings_.domain_max[a];
      r.velocity[a] = std::min(r.velocity[a], 0.0);
      lo[a] -= hi[a] - settings_.domain_max[a];
      moved = true;
    }
    if (lo[a] < settings_.domain_min[a]) {
      r.position[a] += settings_.domain_min[a] - lo[a];
      r.velocity[a] = std::max(r.velocity[a], 0.0);
      moved = true;
    }
  }
  return moved;
}

std::vector<Float4> RigidIce::forces(std::size_t n) const {
  std::vector<Float4> out(n);
  if (n) cl_.queue().enqueueReadBuffer(force_, CL_TRUE, 0, n * 16, out.data());
  return out;
}

RigidIce::Saved RigidIce::save() const {
  Saved s;
  s.bodies = {double(labelled_), double(labelled_step_), double(phase_changed_), double(labellings_)};
  // The last labelling's sweeps, then each body's shape as that labelling left it (particles that have
  // melted since included, as the running solver has it): its particle count and their offsets.
  s.labelling = {double(last_iterations_)};
  for (const auto& shape : shapes_) {
    s.labelling.push_back(double(shape.size()));
    for (const Eigen::Vector3f& o : shape) s.labelling.insert(s.labelling.end(), {o.x(), o.y(), o.z()});
  }
  for (const IceBody& b : bodies_) {
    s.bodies.push_back(double(b.label));
    s.bodies.push_back(double(b.particles));
    s.bodies.push_back(b.radius);
    const std::vector<double> r = to_vector(b.body);
    s.bodies.push_back(double(r.size()));
    s.bodies.insert(s.bodies.end(), r.begin(), r.end());
  }
  return s;
}

void RigidIce::restore(const Saved& s) {
  if (s.bodies.size() < 4) throw Error("rigid ice state: the rigid_bodies section is too short");
  labelled_ = s.bodies[0] != 0;
  labelled_step_ = static_cast<std::uint64_t>(s.bodies[1]);
  phase_changed_ = s.bodies[2] != 0;
  labellings_ = static_cast<std::uint64_t>(s.bodies[3]);
  last_iterations_ = s.labelling.empty() ? 0 : static_cast<int>(s.labelling[0]);
  bodies_.clear();
  std::size_t k = 4;
  while (k < s.bodies.size()) {
    if (k + 4 > s.bodies.size()) throw Error("rigid ice state: a body record is cut short");
    IceBody b;
    b.label = static_cast<std::uint32_t>(s.bodies[k]);
    b.particles = static_cast<std::size_t>(s.bodies[k + 1]);
    b.radius = s.bodies[k + 2];
    const auto len = static_cast<std::size_t>(s.bodies[k + 3]);
    k += 4;
    if (k + len > s.bodies.size()) throw Error("rigid ice state: a body record is cut short");
    b.body =
        body_from_vector(std::vector<double>(s.bodies.begin() + long(k), s.bodies.begin() + long(k + len)));
    k += len;
    bodies_.push_back(std::move(b));
  }
  shapes_.assign(bodies_.size(), {});
  if (s.labelling.size() > 1) {
    std::size_t at = 1;
    for (auto& shape : shapes_) {
      if (at >= s.labelling.size()) throw Error("rigid ice state: the body shapes are cut short");
      const auto count = static_cast<std::size_t>(s.labelling[at++]);
      if (at + 3 * count > s.labelling.size()) throw Error("rigid ice state: the body shapes are cut short");
      for (std::size_t j = 0; j < count; ++j, at += 3)
        shape.emplace_back(float(s.labelling[at]), float(s.labelling[at + 1]), float(s.labelling[at + 2]));
    }
    if (at != s.labelling.size()) throw Error("rigid ice state: the body shapes do not match the bodies");
  } else {
    // Files written before the shapes were kept: each body's particles now (uploaded with the fields).
    const std::size_t n = store_.size();
    std::vector<std::uint32_t> body(n);
    std::vector<Float4> offset(n);
    if (n) {
      cl_.queue().enqueueReadBuffer(store_[body_], CL_FALSE, 0, n * 4, body.data());
      cl_.queue().enqueueReadBuffer(store_[offset_], CL_TRUE, 0, n * 16, offset.data());
    }
    for (std::size_t i = 0; i < n; ++i)
      if (body[i] < bodies_.size()) shapes_[body[i]].emplace_back(offset[i][0], offset[i][1], offset[i][2]);
  }
  upload_bodies();
}

}  // namespace thaw
