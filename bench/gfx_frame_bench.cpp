// Frame pacing of the render thread while cuts stream in (issue 6; benchmark, not a test).
// A G-code program is streamed through the kernel on a geometry thread in (scaled) real
// time (app::PathStreamer, publishing to gfx::SolidExchange); the render thread draws a
// hidden window offscreen at the target rate. Prints frame period p50/p99/max, work per
// frame, regions rebuilt per frame. Needs a display: `xvfb-run -a lbr_gfx_frame_bench ...`.
//
// usage: lbr_gfx_frame_bench PROGRAM [SECONDS=60] [SPEED=1] [WxH=1280x800] [RATE=30] [COLOR=heat]
#include <chrono>
#include <cstdio>
#include <string>
#include <thread>

#include "app/outputs.hpp"
#include "app/profile.hpp"
#include "app/view.hpp"
#include "gfx/render_thread.hpp"
#include "gfx/window.hpp"

int main(int argc, char** argv) {
  using namespace lbr;
  const std::string first = argc > 1 ? argv[1] : "";
  const bool help = first == "--help" || first == "-h";
  if (argc < 2 || help || first[0] == '-') {
    std::fprintf(help ? stdout : stderr,
                 "usage: %s PROGRAM [SECONDS=60] [SPEED=1] [WxH=1280x800] [RATE=30] [COLOR=heat]\n"
                 "Frame pacing of the render thread while PROGRAM streams through the kernel; needs a display\n"
                 "(headless: xvfb-run -a %s PROGRAM 60).\n",
                 argv[0], argv[0]);
    return help ? 0 : 2;
  }
  try {
    const std::string program = argv[1];
    const double seconds = argc > 2 ? std::stod(argv[2]) : 60.0;
    const double speed = argc > 3 ? std::stod(argv[3]) : 1.0;
    gfx::RenderThreadConfig cfg;
    if (argc > 4) gfx::parse_size(argv[4], cfg.width, cfg.height);
    cfg.rate_hz = argc > 5 ? std::stod(argv[5]) : 30.0;
    cfg.render.color = gfx::parse_color_mode(argc > 6 ? argv[6] : "heat");
    cfg.max_frames = static_cast<std::size_t>(seconds * cfg.rate_hz);

    const app::Profile profile = app::default_profile();
    const nc::Toolpath path = app::load_toolpath(program, profile);
    gfx::Window win(cfg.width, cfg.height, false, "lbr_gfx_frame_bench");
    const std::string gl = gfx::Window::gl_description();
    geom::LbrSolid solid(profile.solid);
    solid.clear_dirty();
    gfx::SolidExchange ex;
    app::PathStreamer streamer(profile, path, solid, ex, app::StreamOptions{speed, 0.004, 0.004});
    gfx::RenderThread rt(win, ex, solid, cfg);
    rt.start();
    streamer.start();
    while (rt.running()) std::this_thread::sleep_for(std::chrono::milliseconds(20));
    streamer.stop();
    rt.stop();
    const gfx::PacingReport& r = rt.report();
    if (!r.error.empty()) throw std::runtime_error(r.error);
    using P = gfx::PacingReport;
    std::vector<double> rebuilt(r.regions_rebuilt.begin(), r.regions_rebuilt.end());
    std::vector<double> applied(r.regions_applied.begin(), r.regions_applied.end());
    double sum_rebuilt = 0;
    std::size_t frames_with_rebuild = 0;
    for (double v : rebuilt) {
      sum_rebuilt += v;
      frames_with_rebuild += v > 0 ? 1 : 0;
    }
    double sum_batch = 0, max_batch = 0;
    for (double v : streamer.batch_ms()) {
      sum_batch += v;
      max_batch = std::max(max_batch, v);
    }
    std::printf("program %s | %.0f s at %.0f Hz, speed %gx, %dx%d, %s colour | %s\n", program.c_str(), seconds,
                cfg.rate_hz, speed, cfg.width, cfg.height, gfx::to_string(cfg.render.color), gl.c_str());
    std::printf("frames %llu, late %llu, snapshots %llu (exchange: %llu published, %llu refused)\n",
                static_cast<unsigned long long>(r.frames), static_cast<unsigned long long>(r.late_frames),
                static_cast<unsigned long long>(r.snapshots), static_cast<unsigned long long>(ex.published()),
                static_cast<unsigned long long>(ex.skipped()));
    std::printf("frame period [ms]: p50 %.2f  p99 %.2f  max %.2f\n", P::percentile(r.period_ms, 0.5),
                P::percentile(r.period_ms, 0.99), P::percentile(r.period_ms, 1.0));
    std::printf("work per frame [ms]: p50 %.2f  p99 %.2f  max %.2f\n", P::percentile(r.work_ms, 0.5),
                P::percentile(r.work_ms, 0.99), P::percentile(r.work_ms, 1.0));
    std::printf("mesh rebuild per frame [ms]: p50 %.2f  p99 %.2f  max %.2f\n", P::percentile(r.mesh_ms, 0.5),
                P::percentile(r.mesh_ms, 0.99), P::percentile(r.mesh_ms, 1.0));
    std::printf("regions rebuilt per frame: mean %.2f  p99 %.0f  max %.0f  (frames with a rebuild: %zu); "
                "applied per frame: p99 %.0f max %.0f\n",
                r.frames ? sum_rebuilt / static_cast<double>(r.frames) : 0.0, P::percentile(rebuilt, 0.99),
                P::percentile(rebuilt, 1.0), frames_with_rebuild, P::percentile(applied, 0.99), P::percentile(applied, 1.0));
    std::printf("geometry batches %llu: mean %.2f ms, max %.2f ms\n", static_cast<unsigned long long>(streamer.batches()),
                streamer.batches() ? sum_batch / static_cast<double>(streamer.batches()) : 0.0, max_batch);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "lbr_gfx_frame_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
