// png_probe — pixel facts of a PNG for the CLI tests (no image library in the shell):
//   png_probe FILE                      prints "WIDTH HEIGHT"
//   png_probe FILE count R G B TOL      prints how many pixels are within TOL of (R, G, B) per channel
//   png_probe FILE hue                  prints how many pixels are strongly coloured orange (the
//                                       tool's flute: R > G > B, R − B > 80)
//   png_probe FILE diff OTHER           prints how many pixels differ by more than 24 in a channel
//   png_probe FILE at X Y               prints the pixel at column X, row Y (negative: from the
//                                       right / bottom edge) as "R G B"
// Exit status 2 when the file cannot be read as a PNG.
#include <cstdio>
#include <cstdlib>
#include <string>

#include <stb_image.h>

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: png_probe FILE [count R G B TOL | hue | diff OTHER | at X Y]\n");
    return 2;
  }
  int w = 0, h = 0, n = 0;
  unsigned char* px = stbi_load(argv[1], &w, &h, &n, 3);
  if (px == nullptr) {
    std::fprintf(stderr, "png_probe: %s: %s\n", argv[1], stbi_failure_reason());
    return 2;
  }
  const std::string mode = argc > 2 ? argv[2] : "";
  if (mode == "at" && argc == 5) {
    int x = std::atoi(argv[3]), y = std::atoi(argv[4]);
    if (x < 0) x += w;
    if (y < 0) y += h;
    if (x < 0 || x >= w || y < 0 || y >= h) {
      std::fprintf(stderr, "png_probe: %s: pixel %s %s outside %dx%d\n", argv[1], argv[3], argv[4], w, h);
      stbi_image_free(px);
      return 2;
    }
    const unsigned char* p = px + 3 * (static_cast<long>(y) * w + x);
    std::printf("%d %d %d\n", p[0], p[1], p[2]);
    stbi_image_free(px);
    return 0;
  }
  unsigned char* other = nullptr;
  if (mode == "diff" && argc == 4) {
    int w2 = 0, h2 = 0, n2 = 0;
    other = stbi_load(argv[3], &w2, &h2, &n2, 3);
    if (other == nullptr || w2 != w || h2 != h) {
      std::fprintf(stderr, "png_probe: %s: missing or of another size\n", argv[3]);
      return 2;
    }
  }
  long count = 0;
  for (long i = 0; i < static_cast<long>(w) * h; ++i) {
    const int r = px[3 * i], g = px[3 * i + 1], b = px[3 * i + 2];
    if (mode == "count" && argc == 7) {
      const int tol = std::atoi(argv[6]);
      count += std::abs(r - std::atoi(argv[3])) <= tol && std::abs(g - std::atoi(argv[4])) <= tol &&
               std::abs(b - std::atoi(argv[5])) <= tol;
    } else if (mode == "hue") {
      count += r > g && g > b && r - b > 80;
    } else if (other != nullptr) {
      count += std::abs(r - other[3 * i]) > 24 || std::abs(g - other[3 * i + 1]) > 24 || std::abs(b - other[3 * i + 2]) > 24;
    }
  }
  stbi_image_free(px);
  if (other != nullptr) stbi_image_free(other);
  if (mode.empty()) std::printf("%d %d\n", w, h);
  else std::printf("%ld\n", count);
  return 0;
}
