// Heap allocation counter for the tests that prove a path does not allocate. Linking
// tests/alloc_counter.cpp into a test replaces the global operator new/delete (plain and
// aligned) with counting ones; one copy per executable.
#pragma once

namespace lbr::test {

// Allocations through operator new since the program started.
[[nodiscard]] long allocations() noexcept;

}  // namespace lbr::test
