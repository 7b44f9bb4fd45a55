# Build-time savings for CI's budget (preset "ci", and "arm64" which inherits it): precompiled third-party headers.
# They matter on a machine with no compiler cache, where every build is from scratch; with ccache (developers'
# builds) a precompiled header mostly gets in the way of cache hits, so the option is off unless a preset sets it.
# Measured figures are in tests/run.sh.
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
