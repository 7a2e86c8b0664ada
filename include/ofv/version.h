/**
 * \file version.h
 * \brief Which ofv this is: what episode records and sweep records carry
 *        so that results from different code are never mixed.
 */
#pragma once

namespace ofv {

/// \brief The project's version, e.g. `0.1.0`.
[[nodiscard]] const char* version();

/// \brief The git commit ofv was built from (`git rev-parse HEAD`), with
///        `-dirty` when tracked files differed from it; `unknown` when not
///        built from a git work tree.
[[nodiscard]] const char* git_commit();

}  // namespace ofv
