// Shared by the reliability suite (soak tool, fault tests): the fast simulated booth's configuration, the
// synthetic visitor folder, and the check that a sessions folder holds only complete sessions.
#pragma once

#include "config/booth_config.h"

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace avatarbooth::reliability {

// The simulated booth (sim camera showing `visitorFolder`, sim buttons, headless display) with the flow's waits
// shortened so that a visitor session takes seconds instead of half a minute; sessions go to `sessions`. The
// flow's logic is unchanged: only its durations are (set in code, below the limits a config file allows).
BoothConfig fastSimBooth(const std::filesystem::path& visitorFolder, const std::filesystem::path& sessions);

// The synthetic visitor's recorded folder under `dir` (made once, then reused).
std::filesystem::path syntheticVisitorFolder(const std::filesystem::path& dir);

// What a sessions folder holds.
struct SessionsCheck {
    std::vector<std::string> complete;    // codes of complete sessions
    std::vector<std::string> problems;    // one line per incomplete or corrupt session, or stray file
    int leftovers = 0;                    // entries under .pending/ and .trash-* (removed at the next start)
    std::vector<std::string> leftoverNames;  // those under .pending/ and .trash-*, by name
    int withToon = 0;                     // complete or not, sessions holding their toon strip (toon/)
};

// The files every kept session has.
const std::vector<std::string>& sessionFiles();

// Checks every folder: all of sessionFiles() present and non-empty, no temporary file, session.json and fit.json
// parse, avatar.glb has a consistent GLB header (the Khronos validator is run separately: validateGlb), and toon/
// (the toon strip, added after the keep) absent or whole. A kept session's ".toon.partial-*" (a strip being written
// when the booth was killed) counts as a leftover.
SessionsCheck checkSessions(const std::filesystem::path& sessions);

// Runs the Khronos glTF validator (tests/gltf, npm); true when it reports no errors. `report` gets its output.
bool validateGlb(const std::filesystem::path& glb, std::string* report = nullptr);
bool haveGltfValidator();

// A fingerprint of every file of a session (relative name -> FNV-1a hash; leftovers ".partial-*" left out), to
// show it was not touched.
std::map<std::string, std::uint64_t> fingerprint(const std::filesystem::path& folder);

// What changed between two fingerprints of a kept session (empty: nothing). The toon strip may appear after the
// keep (the keep does not wait for the toon), so a toon/ that was absent before may have appeared; every other
// file, and a toon/ that was already there, must be exactly as before.
std::vector<std::string> changesSince(const std::map<std::string, std::uint64_t>& before,
                                      const std::map<std::string, std::uint64_t>& now);

// The bound for "back serving within 2 s of the fault clearing (or of the restart)". The 2 s is the issue's
// figure for a booth that has its cores; when the machine is busier than its cores (load average above the core
// count: parallel builds, a CI neighbour) the test keeps only a bound that still catches a hang (10 s), and the
// figure printed beside it says what was measured.
double recoveryBoundSeconds();

}  // namespace avatarbooth::reliability
