#include "server/render_worker.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "render/egl_context.h"
#include "render/image_io.h"
#include "render/particle_view.h"
#include "render/picking.h"
#include "render/surface_renderer.h"
#include "server/session.h"
#include "sim/error.h"

namespace thaw {

using Clock = std::chrono::steady_clock;

namespace {

double ms_since(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

// Frames a second the pixel budget allows for frames drawn with `o` (RenderWorker::fps_limit): the
// surface view marches scale^2 of the pixels.
double budget_fps(const RenderOptions& o) {
  const bool surface = o.view == "surface";
  const double weight = surface && o.quality == "full" ? RenderWorker::kFullQualityWeight : 1.0;
  const double marched = surface ? double(SurfaceRenderer::marched(o.width, o.scale)) *
                                       SurfaceRenderer::marched(o.height, o.scale)
                                 : double(o.width) * o.height;
  return RenderWorker::kMaxPixelsPerSecond / (marched * weight);
}

Clock::duration seconds(double s) {
  return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
}

}  // namespace

// The GL side, made on the render thread the first time the surface view is drawn. FrameRenderer would
// fix the view at construction; a camera drag changes it many times a second, and a new EGL context and
// shader build per change would cost more than the frame.
struct RenderWorker::Gl {
  EglContext context;
  SurfaceRenderer surface{context};
  std::shared_ptr<const DensityFields> fields;  // what `surface` holds uploaded
};

RenderWorker::RenderWorker(Session& session, RenderOptions options, std::function<void()> on_frame)
    : session_(session), on_frame_(std::move(on_frame)), options_(std::move(options)) {}

RenderWorker::~RenderWorker() { stop(); }

void RenderWorker::start() {
  {
    std::lock_guard lock(mutex_);
    if (thread_.joinable() || stop_) return;
  }
  // Outside mutex_: the session calls its listeners under its own lock, and this one then takes mutex_.
  listener_ = session_.subscribe([this] {
    {
      std::lock_guard l(mutex_);
      snapshot_pending_ = true;
    }
    cv_.notify_all();
  });
  thread_ = std::thread(&RenderWorker::run, this);
}

void RenderWorker::stop() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  cv_.notify_all();
  if (thread_.joinable()) thread_.join();
  if (listener_) session_.unsubscribe(listener_);
  listener_ = 0;
}

void RenderWorker::run() {
  auto next_allowed = Clock::now(), next_budget = Clock::now();
  std::uint64_t drawn_version = 0;
  for (;;) {
    RenderOptions options;
    int quality = 80;
    double fps = 30;
    bool moving = false;
    {
      std::unique_lock lock(mutex_);
      const auto settle_at = [&] { return moved_at_ + seconds(kSettleSeconds); };
      const auto ready = [&] {
        const bool settled = settle_due_ && Clock::now() >= settle_at();
        return stop_ || ((snapshot_pending_ || options_version_ != drawn_version || settled) &&
                         (watched_ || frames_ == 0));
      };
      // A frame drawn while the camera moved is followed by one at the chosen scale once it stops.
      while (!ready()) {
        if (settle_due_)
          cv_.wait_until(lock, settle_at());
        else
          cv_.wait(lock);
      }
      // The fps cap: changes that arrive meanwhile merge into the next frame instead of queueing.
      if (!stop_ && Clock::now() < next_budget) cv_.wait_until(lock, next_budget, [&] { return stop_; });
      if (!stop_ && !hurry_ && Clock::now() < next_allowed)
        cv_.wait_until(lock, next_allowed, [&] { return stop_ || hurry_; });
      if (stop_) break;
      hurry_ = false;
      snapshot_pending_ = false;
      drawn_version = options_version_;
      options = options_;
      quality = jpeg_quality_;
      fps = std::min(fps_, budget_fps(options_));
      moving = options.view == "surface" && options.scale > kMovingScale && Clock::now() < settle_at();
      settle_due_ = moving;
    }
    if (moving) options.scale = kMovingScale;
    const auto started = Clock::now();
    next_allowed = started + seconds(1.0 / fps);
    // hurry() skips the frame-rate cap, not the pixel budget: commands at 50 a second must not turn
    // into 50 large frames a second.
    next_budget = started + seconds(1.0 / budget_fps(options));
    if (auto snapshot = session_.latest_snapshot()) render_one(snapshot, options, quality, moving);
  }
  // The context belongs to this thread: release it here, not in the destructor's thread.
  gl_.reset();
}

bool RenderWorker::render_one(const std::shared_ptr<const RenderSnapshot>& snapshot,
                              const RenderOptions& options, int jpeg_quality, bool moving) {
  const auto t0 = Clock::now();
  try {
    const OrbitCamera camera = camera_for(options, *snapshot);
    std::shared_ptr<const DensityFields> fields;
    Image image;
    std::string renderer;
    if (options.view == "surface") {
      if (gl_failed_) return false;  // said so in status() once; retrying every frame would spam the log
      if (!gl_) {
        try {
          gl_ = std::make_unique<Gl>();
        } catch (const std::exception& e) {
          gl_failed_ = true;
          set_status(std::string("error: the surface view needs EGL: ") + e.what());
          std::fprintf(stderr, "thaw serve: no frames: %s\n", e.what());
          return false;
        }
      }
      gl_->surface.set_quality(options.quality == "fast" ? SurfaceRenderer::Quality::Fast
                                                         : SurfaceRenderer::Quality::Full);
      gl_->surface.set_sources(snapshot->dryers, snapshot->lamps);
      gl_->surface.set_scale(options.scale);
      const FieldOptions wanted = tint_.apply(surface_fields(options), snapshot->time);
      const bool same = gl_->fields && uploaded_ == snapshot && uploaded_field_options_ == wanted;
      if (same) {
        // Only the camera moved (e.g. orbiting a paused scene): draw the uploaded fields again.
        fields = gl_->fields;
        image = gl_->surface.render(camera);
      } else {
        fields = std::make_shared<const DensityFields>(build_density_fields(*snapshot, wanted));
        image = gl_->surface.render(*fields, camera);
        gl_->fields = fields;
        uploaded_ = snapshot;
        uploaded_field_options_ = wanted;
        tint_.remember(wanted, *fields, snapshot->time);
        // As the next frame of this snapshot will ask: with the reference just latched, the same fields.
        uploaded_field_options_ = tint_.apply(wanted, snapshot->time);
      }
      renderer = gl_->context.description();
    } else {
      image = render_cpu_view(options, *snapshot, camera);
      renderer = "CPU " + options.view + " view";
    }
    const double render_ms = ms_since(t0);
    const auto t1 = Clock::now();
    auto frame = std::make_shared<EncodedFrame>();
    frame->jpeg = encode_jpeg(image, jpeg_quality);
    frame->encode_ms = ms_since(t1);
    frame->render_ms = render_ms;
    frame->scale = options.view == "surface" ? options.scale : 1.0;
    frame->moving = moving;
    frame->frame = ++frames_;
    frame->sim_time = snapshot->time;
    frame->step = snapshot->step;
    frame->width = image.width;
    frame->height = image.height;
    set_status("ok: " + renderer);  // before the frame, so whoever sees the frame sees the status too
    {
      std::lock_guard lock(frame_mutex_);
      frame_ = std::move(frame);
      finished_.push_back(Clock::now());
      while (finished_.size() > 256) finished_.pop_front();
      picked_snapshot_ = snapshot;
      picked_fields_ = fields;
      picked_camera_ = camera;
      picked_field_options_ = options.field;
      pick_has_camera_ = options.view != "slice";
    }
    frame_cv_.notify_all();
    if (on_frame_) on_frame_();
    return true;
  } catch (const std::exception& e) {
    set_status(std::string("error: ") + e.what());
    return false;
  }
}

void RenderWorker::set_status(std::string s) {
  std::lock_guard lock(mutex_);
  status_ = std::move(s);
}

std::string RenderWorker::status() const {
  std::lock_guard lock(mutex_);
  return status_;
}

std::shared_ptr<const EncodedFrame> RenderWorker::latest_frame() const {
  std::lock_guard lock(frame_mutex_);
  return frame_;
}

std::shared_ptr<const EncodedFrame> RenderWorker::wait_for_frame(std::uint64_t after,
                                                                 std::chrono::milliseconds timeout) const {
  std::unique_lock lock(frame_mutex_);
  frame_cv_.wait_for(lock, timeout, [&] { return frame_ && frame_->frame > after; });
  return frame_;
}

// ---- settings ------------------------------------------------------------------------------------------

void RenderWorker::set_camera(std::optional<double> azimuth, std::optional<double> elevation,
                              std::optional<double> distance, std::optional<Eigen::Vector3d> target,
                              std::optional<double> fov) {
  if (azimuth && !std::isfinite(*azimuth)) throw Error("camera: azimuth must be finite");
  if (elevation && !(std::abs(*elevation) < 90.0))
    throw Error("camera: elevation must be between -90 and 90 degrees");
  if (distance && !(*distance > 0 && std::isfinite(*distance)))
    throw Error("camera: distance must be positive");
  if (target && !target->allFinite()) throw Error("camera: target must be finite");
  if (fov && !(*fov >= 5.0 && *fov <= 120.0)) throw Error("camera: fov must be 5..120 degrees");
  {
    std::lock_guard lock(mutex_);
    if (azimuth) options_.azimuth = std::remainder(*azimuth, 360.0);
    if (elevation) options_.elevation = *elevation;
    if (distance) options_.distance = *distance;
    if (target) {
      options_.target = *target;
      options_.has_target = true;
    }
    if (fov) options_.fov = *fov;
    ++options_version_;
    moved_at_ = Clock::now();
  }
  cv_.notify_all();
}

void RenderWorker::reset_camera(const SceneCamera& camera) {
  {
    std::lock_guard lock(mutex_);
    use_camera(options_, camera);
    ++options_version_;
  }
  cv_.notify_all();
}

void RenderWorker::orbit(double d_azimuth, double d_elevation, double zoom) {
  if (!std::isfinite(d_azimuth) || !std::isfinite(d_elevation) || !(zoom > 0 && std::isfinite(zoom)))
    throw Error("camera.orbit: angles must be finite and zoom positive");
  // Zooming starts from the distance drawn now, and stays within what camera_for allows of the
  // distance that frames the domain: repeated zooms out no longer pile up past it.
  double drawn = 0, framing = 0;
  if (auto s = session_.latest_snapshot()) {
    RenderOptions o = options();
    drawn = camera_for(o, *s).distance;
    o.distance = 0;
    framing = camera_for(o, *s).distance;
  }
  {
    std::lock_guard lock(mutex_);
    options_.azimuth = std::remainder(options_.azimuth + d_azimuth, 360.0);
    options_.elevation = std::clamp(options_.elevation + d_elevation, -89.0, 89.0);
    if (zoom != 1.0 && drawn > 0)
      options_.distance = std::clamp(drawn * zoom, kClosest * framing, kFarthest * framing);
    ++options_version_;
    moved_at_ = Clock::now();
  }
  cv_.notify_all();
}

void RenderWorker::set_view(const std::string& view, std::optional<std::string> colour_by,
                            std::optional<double> tint_reference) {
  if (view != "surface" && view != "particles" && view != "slice")
    throw Error("view: unknown view '" + view + "'; available: surface, particles, slice");
  if (colour_by) check_colouring(*colour_by, "colour_by");
  if (tint_reference && !(*tint_reference >= 0 && *tint_reference <= kMaxTintReference))
    throw Error("tint_reference: expected a concentration in [0, " + format_number(kMaxTintReference) +
                "] g/L");
  {
    std::lock_guard lock(mutex_);
    options_.view = view;
    if (colour_by) options_.colour_by = *colour_by;
    if (tint_reference) options_.field.tint_reference = static_cast<float>(*tint_reference);
    ++options_version_;
  }
  cv_.notify_all();
}

void RenderWorker::set_quality(std::optional<int> width, std::optional<int> height,
                               std::optional<int> jpeg_quality, std::optional<double> fps,
                               std::optional<std::string> surface, std::optional<double> scale) {
  if (width && (*width < 16 || *width > 1920)) throw Error("quality: width must be 16..1920 pixels");
  if (height && (*height < 16 || *height > 1080)) throw Error("quality: height must be 16..1080 pixels");
  if (jpeg_quality && (*jpeg_quality < 10 || *jpeg_quality > 95))
    throw Error("quality: jpeg_quality must be 10..95");
  if (fps && !(*fps >= 1 && *fps <= 60)) throw Error("quality: fps must be 1..60");
  if (surface && *surface != "full" && *surface != "fast")
    throw Error("quality: surface must be full or fast");
  if (scale && !(*scale >= SurfaceRenderer::kMinScale && *scale <= 1.0))
    throw Error("quality: scale must be 0.25..1 (the fraction of width and height the surface march draws)");
  {
    std::lock_guard lock(mutex_);
    if (width) options_.width = *width;
    if (height) options_.height = *height;
    if (jpeg_quality) jpeg_quality_ = *jpeg_quality;
    if (fps) fps_ = *fps;
    if (surface) options_.quality = *surface;
    if (scale) options_.scale = *scale;
    ++options_version_;
  }
  cv_.notify_all();
}

RenderOptions RenderWorker::options() const {
  std::lock_guard lock(mutex_);
  return options_;
}

int RenderWorker::jpeg_quality() const {
  std::lock_guard lock(mutex_);
  return jpeg_quality_;
}

double RenderWorker::fps_cap() const {
  std::lock_guard lock(mutex_);
  return fps_;
}

double RenderWorker::fps_limit() const {
  std::lock_guard lock(mutex_);
  return std::min(fps_, budget_fps(options_));
}

void RenderWorker::hurry() {
  {
    std::lock_guard lock(mutex_);
    hurry_ = true;
  }
  cv_.notify_all();
}

void RenderWorker::set_watched(bool watched) {
  {
    std::lock_guard lock(mutex_);
    watched_ = watched;
  }
  cv_.notify_all();
}

double RenderWorker::fps() const {
  constexpr double window_s = 2.0;
  const auto now = Clock::now();
  std::lock_guard lock(frame_mutex_);
  const auto from = now - seconds(window_s);
  std::size_t n = 0;
  for (const auto t : finished_) n += t >= from;
  return double(n) / window_s;
}

// ---- picking -------------------------------------------------------------------------------------------

std::optional<RenderWorker::Pick> RenderWorker::pick(double x, double y) const {
  std::shared_ptr<const RenderSnapshot> snapshot;
  std::shared_ptr<const DensityFields> fields;
  OrbitCamera camera;
  FieldOptions field_options;
  {
    std::lock_guard lock(frame_mutex_);
    if (!picked_snapshot_ || !pick_has_camera_) return std::nullopt;
    snapshot = picked_snapshot_;
    fields = picked_fields_;
    camera = picked_camera_;
    field_options = picked_field_options_;
  }
  if (!fields) {
    // The particle view draws no fields; build them here, on the caller's thread, and keep them for
    // the next pick on the same frame.
    fields = std::make_shared<const DensityFields>(build_density_fields(*snapshot, field_options));
    std::lock_guard lock(frame_mutex_);
    if (picked_snapshot_ == snapshot && !picked_fields_) picked_fields_ = fields;
  }
  Eigen::Vector3d hit, normal;
  if (!thaw::pick(*fields, camera, x, y, hit, normal)) return std::nullopt;
  return Pick{hit, normal};
}

}  // namespace thaw
