// Names of the iBUG 68-point landmarks as feature files and reports use them ("ibug_07").
#pragma once

#include <cstdio>
#include <string>

namespace avatarbooth {

inline std::string landmarkName(int k) {
    char name[24];  // room for any int, which the compiler checks
    std::snprintf(name, sizeof name, "ibug_%02d", k);
    return name;
}

}  // namespace avatarbooth
