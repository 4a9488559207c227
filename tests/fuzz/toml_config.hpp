// toml++ as the fuzz target compiles it (forced in front of every source, tests/fuzz/
// CMakeLists.txt): header-only, so that its parser is instrumented, and built as dem2d ships
// it. dem2d links Debian's libtomlplusplus, compiled by GCC with NDEBUG, where the library's
// TOML_ASSERT and TOML_ASSERT_ASSUME are no-ops. Its debug assertions are not: with them the
// malformed header "[[:material]]" aborts in parse_key (toml++ 3.3.0; upstream
// marzer/tomlplusplus PR #301), where the shipped parser reports a syntax error (exit 2).
#pragma once

#define TOML_HEADER_ONLY 1
#define TOML_ASSERT(expr) static_cast<void>(0)
