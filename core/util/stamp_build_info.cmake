# Writes build_info.cpp with the current git revision, at every build (not only when
# CMake configures), so results name the revision the binary was built from (with
# "-dirty" when tracked files differ from it). The file is rewritten only when its text
# changes, so an unchanged revision recompiles nothing.
# Arguments: -DSOURCE_DIR=... -DINPUT=build_info.cpp.in -DOUTPUT=build_info.cpp
execute_process(COMMAND git rev-parse --short=12 HEAD
  WORKING_DIRECTORY ${SOURCE_DIR} OUTPUT_VARIABLE GILAB_GIT_REVISION
  OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
if(NOT GILAB_GIT_REVISION)
  set(GILAB_GIT_REVISION "unknown")
else()
  # A build from uncommitted changes to tracked files says so: "<revision>-dirty".
  # --no-optional-locks: a build never writes the repository's index.
  execute_process(COMMAND git --no-optional-locks status --porcelain --untracked-files=no
    WORKING_DIRECTORY ${SOURCE_DIR} OUTPUT_VARIABLE GILAB_GIT_CHANGES
    OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
  if(GILAB_GIT_CHANGES)
    set(GILAB_GIT_REVISION "${GILAB_GIT_REVISION}-dirty")
  endif()
endif()
set(GILAB_SOURCE_DIR ${SOURCE_DIR})
configure_file(${INPUT} ${OUTPUT} @ONLY)
