# Run at every build (cmake -P): writes OUTPUT, a source file defining
# ofv::version() and ofv::git_commit(), when what it would hold changed.
# The commit is `git rev-parse HEAD` of SOURCE_DIR, with "-dirty" when
# tracked files differ from it; "unknown" outside a git work tree.
set(commit unknown)
find_package(Git QUIET)
if(GIT_FOUND)
  execute_process(COMMAND ${GIT_EXECUTABLE} -C ${SOURCE_DIR} rev-parse HEAD
                  OUTPUT_VARIABLE head OUTPUT_STRIP_TRAILING_WHITESPACE RESULT_VARIABLE failed ERROR_QUIET)
  if(NOT failed AND head MATCHES "^[0-9a-f]+$")
    set(commit ${head})
    execute_process(COMMAND ${GIT_EXECUTABLE} -C ${SOURCE_DIR} status --porcelain --untracked-files=no
                    OUTPUT_VARIABLE changes RESULT_VARIABLE failed ERROR_QUIET)
    if(failed OR NOT changes STREQUAL "")
      string(APPEND commit "-dirty")
    endif()
  endif()
endif()
set(text "// Generated at build time by cmake/OfvBuildInfo.cmake: do not edit.
#include \"ofv/version.h\"

namespace ofv {
const char* version() { return \"${VERSION}\"; }
const char* git_commit() { return \"${commit}\"; }
}  // namespace ofv
")
set(old "")
if(EXISTS ${OUTPUT})
  file(READ ${OUTPUT} old)
endif()
if(NOT old STREQUAL text)
  file(WRITE ${OUTPUT} "${text}")
endif()
