#pragma once
// The render thread of `thaw serve` (docs/ARCHITECTURE.md, Server): it owns the EGL context (created on this
// thread, the only one that may use it), renders the session's newest snapshot in the current view, encodes
// it to JPEG once for every viewer and publishes the newest frame; the network loop takes it from there.
// Frames are never queued: a snapshot that arrives while a frame is being rendered replaces any older
// one waiting, so the worker always draws the latest state and falls behind by at most one frame.
//
// One set of view options serves every viewer, because a frame is encoded once for all. Per-client
// cameras would need a render (and an encode) per client, i.e. per-client RenderOptions here and a
// frame per camera; the cost on llvmpipe (~100 ms a surface frame) is why that waits.
#include <Eigen/Core>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "render/camera.h"
#include "render/density_field.h"
#include "render/snapshot.h"
#include "server/render_options.h"

namespace thaw {

class Session;

// One encoded frame, shared by every client that sends it.
struct EncodedFrame {
  std::uint64_t frame = 0;  // 1, 2, ... in the order rendered
  double sim_time = 0;      // [s] of the snapshot drawn
  std::uint64_t step = 0;   // of the snapshot drawn
  int width = 0, height = 0;
  std::string jpeg;
  double render_ms = 0;  // drawing, read-back included
  double scale = 1.0;    // the fraction of width and height the surface march drew (1: every pixel)
  bool moving = false;   // drawn while the camera moved, at kMovingScale
  double encode_ms = 0;
};

class RenderWorker {
 public:
  // `on_frame` runs on the render thread after each new frame (e.g. lws_cancel_service); keep it quick.
  // `session` must outlive the worker (the worker subscribes to its publishes until stop()).
  RenderWorker(Session& session, RenderOptions options = {}, std::function<void()> on_frame = {});
  ~RenderWorker();  // stops
  RenderWorker(const RenderWorker&) = delete;
  RenderWorker& operator=(const RenderWorker&) = delete;

  void start();
  void stop();

  // ---- view settings (thread-safe; the next frame uses them) ------------------------------------------
  // Absent values keep theirs. Throws Error on a value out of range (elevation in (-90, 90), distance
  // > 0, fov in [5, 120]), changing nothing.
  void set_camera(std::optional<double> azimuth, std::optional<double> elevation,
                  std::optional<double> distance, std::optional<Eigen::Vector3d> target,
                  std::optional<double> fov);
  // Back to a scene's own camera (its `camera` block): on scene changes and camera.reset.
  void reset_camera(const SceneCamera& camera);
  // Relative: degrees added to azimuth and elevation (clamped to +-89), distance multiplied by zoom.
  void orbit(double d_azimuth, double d_elevation, double zoom);
  // view: surface | particles | slice; colour_by: phase | temperature | speed.
  // `tint_reference`: the surface view's full-colour concentration when coloured by a substance [g/L]; 0:
  // latched from the first frame (TintLatch).
  void set_view(const std::string& view, std::optional<std::string> colour_by = {},
                std::optional<double> tint_reference = {});
  // width 16..1920, height 16..1080, jpeg_quality 10..95, fps cap 1..60, surface full | fast, scale
  // SurfaceRenderer::kMinScale..1.
  void set_quality(std::optional<int> width, std::optional<int> height, std::optional<int> jpeg_quality,
                   std::optional<double> fps, std::optional<std::string> surface,
                   std::optional<double> scale = {});
  RenderOptions options() const;
  int jpeg_quality() const;
  double fps_cap() const;  // as asked for with set_quality
  // The frame rate the worker draws at most: fps_cap(), lowered so that the pixels drawn a second stay
  // within kMaxPixelsPerSecond (full-quality surfaces weigh kFullQualityWeight: measured on llvmpipe,
  // 67 ms against 43 for fast at 640x480, 353 against 269 at 1920x1080); the surface view counts the
  // pixels its march draws (scale squared). The service's 640x480 fast frame marched at 3/4 is 2.6 Mpx/s
  // at the default 15 frames a second; every pixel at full quality is held to 13 frames a second, and
  // 1920x1080 at full quality to 1.9.
  double fps_limit() const;
  static constexpr double kMaxPixelsPerSecond = 6e6, kFullQualityWeight = 1.5;
  // While the camera moves (camera.orbit, camera.set) and for kSettleSeconds after, surface frames march
  // at most kMovingScale of the width and height (a quarter of the pixels), so a drag answers at the frame
  // rate; then one frame at the chosen scale follows, paused or not.
  static constexpr double kMovingScale = 0.5, kSettleSeconds = 0.3;
  // The next frame starts without waiting for the fps cap: someone waits to see a command's effect.
  void hurry();
  // Whether anyone receives frames; unwatched, the worker draws only its first frame (for picking).
  void set_watched(bool watched);
  // Frames finished per second over the last two seconds.
  double fps() const;

  // ---- what the worker publishes (thread-safe) -----------------------------------------------------
  std::shared_ptr<const EncodedFrame> latest_frame() const;
  // Waits until a frame numbered above `after` exists or `timeout` passes; returns the newest (or null).
  std::shared_ptr<const EncodedFrame> wait_for_frame(std::uint64_t after,
                                                     std::chrono::milliseconds timeout) const;
  // "starting", "ok: <renderer>", or "error: <what failed>" (e.g. no EGL): without a renderer the worker
  // keeps running, just without frames, and says why here.
  std::string status() const;

  // The surface point under pixel (x, y) of the last frame (pixels from the top left), with its outward
  // normal; nothing when the ray misses, before the first frame, or in the slice view (it has no camera).
  // Runs on the calling thread on the last frame's fields, built here when the view did not need them.
  struct Pick {
    Eigen::Vector3d hit, normal;
  };
  std::optional<Pick> pick(double x, double y) const;

 private:
  void run();
  bool render_one(const std::shared_ptr<const RenderSnapshot>& snapshot, const RenderOptions& options,
                  int jpeg_quality, bool moving = false);
  void set_status(std::string s);

  Session& session_;
  std::function<void()> on_frame_;
  int listener_ = 0;

  mutable std::mutex mutex_;
  std::condition_variable cv_;
  RenderOptions options_;
  int jpeg_quality_ = 80;
  // 15 frames a second: above the 12 a moving picture needs with room for a slow frame, and on 2 cores
  // the fast 640x480 frame (about 50 ms beside the simulation) leaves it a quarter of the time between
  // frames (a client can ask for up to 60 with quality.set).
  double fps_ = 15.0;
  bool hurry_ = false;
  std::chrono::steady_clock::time_point moved_at_{};  // the camera's last move
  bool settle_due_ = false;                           // a frame was drawn at kMovingScale
  bool watched_ = true;
  std::uint64_t options_version_ = 1;
  bool snapshot_pending_ = true;  // the session published since the last frame began
  bool stop_ = false;
  std::thread thread_;
  std::string status_ = "starting";

  // Published frame, and what pick() needs of it.
  mutable std::mutex frame_mutex_;
  std::deque<std::chrono::steady_clock::time_point> finished_;  // when recent frames were done, for fps()
  mutable std::condition_variable frame_cv_;
  std::shared_ptr<const EncodedFrame> frame_;
  std::shared_ptr<const RenderSnapshot> picked_snapshot_;
  mutable std::shared_ptr<const DensityFields> picked_fields_;  // built lazily by pick() in other views
  OrbitCamera picked_camera_;
  FieldOptions picked_field_options_;
  bool pick_has_camera_ = false;

  // Render-thread only: the GL objects and what was last uploaded.
  struct Gl;
  std::unique_ptr<Gl> gl_;
  bool gl_failed_ = false;
  std::shared_ptr<const RenderSnapshot> uploaded_;
  FieldOptions uploaded_field_options_;
  TintLatch tint_;  // the render thread's
  std::uint64_t frames_ = 0;
};

}  // namespace thaw
