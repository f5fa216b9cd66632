// gfx/src/gl_util.hpp — private: shader compilation helpers (GL context must be current).
#pragma once

#include <string>

#include <epoxy/gl.h>

namespace lbr::gfx::detail {

// Compiles and links a vertex + fragment shader pair; throws std::runtime_error with the
// info log on failure.
GLuint make_program(const char* vs, const char* fs, const char* name);

}  // namespace lbr::gfx::detail
