// libFuzzer target: the STL reader (verify/stl.hpp, docs/formats.md#stl). Either it returns a
// mesh whose vertices are finite and inside the kernel's safe range, whose binary form reads
// back to a mesh that writes the same bytes (a fixed point), and whose ASCII form reads back to
// as many triangles; or it throws StlError naming the input ("fuzz.stl:LINE: ..." or
// "fuzz.stl: ...").
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "geom/units.hpp"
#include "verify/stl.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view in(reinterpret_cast<const char*>(data), size);
  try {
    const lbr::verify::StlMesh m = lbr::verify::parse_stl(in, "fuzz.stl");
    for (const lbr::verify::Triangle& t : m.triangles)
      for (const lbr::geom::Vec3& v : t.v)
        for (double c : {v.x, v.y, v.z})
          if (!std::isfinite(c) || std::abs(c) > lbr::geom::kSafeRangeMm) __builtin_trap();
    const std::string bin = lbr::verify::stl_binary(m);
    const lbr::verify::StlMesh b = lbr::verify::parse_stl(bin, "fuzz-binary.stl");
    if (b.triangles.size() != m.triangles.size() || lbr::verify::stl_binary(b) != bin) __builtin_trap();
    const lbr::verify::StlMesh a = lbr::verify::parse_stl(lbr::verify::stl_ascii(m), "fuzz-ascii.stl");
    if (a.triangles.size() != m.triangles.size()) __builtin_trap();
  } catch (const lbr::verify::StlError& e) {
    if (std::string_view(e.what()).substr(0, 8) != "fuzz.stl") __builtin_trap();
  }
  return 0;
}
