# Build-time savings for a build from scratch (the presets "release", which the README's two commands use, "ci" and
# "arm64"): precompiled third-party headers, made once for the first of the booth's libraries and reused by the
# others. With ccache a precompiled header mostly gets in the way of cache hits: a developer with a compiler cache
# configures with -DAVATARBOOTH_PCH=OFF. The README ("The two commands", "Building for the board") has the figures.
option(AVATARBOOTH_PCH "Precompile the third-party headers most sources include (OpenCV, JSON, spdlog, GoogleTest)"
       OFF)

# The standard and third-party headers a target's sources share; parsed once per target instead of once per file.
set(AVATARBOOTH_PCH_STD <string> <vector> <map> <memory> <optional> <functional> <algorithm> <filesystem> <chrono>
    <fstream> <sstream>)
set(AVATARBOOTH_PCH_OPENCV <opencv2/core.hpp> <opencv2/imgproc.hpp>)

# avatarbooth_precompile_headers(TARGET HEADER...): precompile HEADER... (in <> form) for TARGET when the option is
# on. Only for targets with several sources: making the header costs about what parsing it in two files does.
function(avatarbooth_precompile_headers target)
  if(AVATARBOOTH_PCH)
    target_precompile_headers(${target} PRIVATE ${ARGN})
  endif()
endfunction()

# The tests' own code (not the booth's, which they link as built) compiled without optimisation in CI: it is
# assertions and set-up, and -O0 compiles a test source in about 30 % less time than -O2. The data tests stay at
# the build's level: their helpers search meshes and scans vertex by vertex. Empty: the build type's flags.
set(AVATARBOOTH_TEST_CODE_OPT "" CACHE STRING "Optimisation flag for the unit, integration, e2e, kernel and reliability tests' own sources (e.g. -O0)")

# avatarbooth_test_code_opt(TARGET): compile TARGET's own sources with AVATARBOOTH_TEST_CODE_OPT when it is set.
function(avatarbooth_test_code_opt target)
  if(AVATARBOOTH_TEST_CODE_OPT)
    target_compile_options(${target} PRIVATE ${AVATARBOOTH_TEST_CODE_OPT})
  endif()
endfunction()

# Unity builds of the booth's libraries, its executable and the test executables (CMake's UNITY_BUILD, batches of 8
# sources): each batch parses the shared headers and instantiates the shared templates (OpenCV, dlib, JSON, spdlog,
# GLM, GoogleTest) once instead of once per file. On by the ci presets (ci, arm64, trixie: three builds from scratch
# in every CI run); off for developers, whose incremental builds would recompile a whole batch for one file. The
# sources of a batch share one translation unit, so two helpers of the same name in anonymous namespaces of one
# target clash, and a file-scope `using namespace` reaches the files after it: give a test's helper a name of its
# own, or share it through a header (tests/test_paths.h); a source that must keep such a helper sets
# SKIP_UNITY_BUILD_INCLUSION (sim/CMakeLists.txt, Xlib's macros in tests/CMakeLists.txt). GCC's
# -Wsubobject-linkage is meant for headers and fires on a source's own anonymous types once it is included into a
# batch: it is off in a unity build. The README ("Building for the board") has the figures.
option(AVATARBOOTH_UNITY "Unity builds of the booth's own libraries and of the tests" OFF)
set(CMAKE_UNITY_BUILD_BATCH_SIZE 8)
if(AVATARBOOTH_UNITY AND CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
  add_compile_options(-Wno-subobject-linkage)
endif()
