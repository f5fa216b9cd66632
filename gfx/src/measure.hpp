// gfx/src/measure.hpp — private: the Measure tool's pick (docs/ui.md). A tap's line of
// sight (Camera::ray) is cast against the level polygons of the render side's mirror solid
// (geom/probe.hpp), on the side of the section plane that is drawn. Render thread; no
// allocation, no GL.
#pragma once

#include "geom/lbr_solid.hpp"
#include "gfx/camera.hpp"
#include "gfx/renderer.hpp"
#include "gfx/ui.hpp"

namespace lbr::gfx::detail {

// The point of the part under window point (x, y) of a w × h view; false when the line of
// sight meets no material there.
[[nodiscard]] bool measure_at(const geom::LbrSolid& solid, const Camera& cam, const RenderOptions& opt, double x,
                              double y, int w, int h, MeasurePoint& out) noexcept;

}  // namespace lbr::gfx::detail
