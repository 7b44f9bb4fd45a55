// GPIO lines below the button logic: levels and edges of input lines, levels of output lines. One implementation
// per kernel interface (libgpiod 1.6 today, 2.x beside it later) plus the scripted simulation, so debouncing,
// naming and event order are written once (DebouncedButtons, LineLamps).
#pragma once

#include "common/clock.h"

#include <cstddef>
#include <string>
#include <vector>

namespace avatarbooth {

// One edge of input line `line` (an index into the lines as requested): its level after the edge.
struct RawEdge {
    std::size_t line = 0;
    bool high = false;
    SteadyTime time;

    bool operator==(const RawEdge&) const = default;
};

// A set of input lines watched for edges.
class RawInputLines {
public:
    virtual ~RawInputLines() = default;
    // The current level of every line (true = high), in request order.
    virtual std::vector<bool> levels() = 0;
    // Waits until edges arrive or `deadline` passes; returns the edges that arrived, in time order (empty at the
    // deadline). A deadline in the past only collects edges already waiting.
    virtual std::vector<RawEdge> waitEdges(SteadyTime deadline) = 0;
    // The clock the edges are stamped with.
    virtual SteadyTime now() const = 0;
    // Which chip and lines, for logs.
    virtual std::string describe() const = 0;
    // True when no edge will ever come again (a script that has run out).
    virtual bool exhausted() const { return false; }
};

// A set of output lines (lamps, relays).
class RawOutputLines {
public:
    virtual ~RawOutputLines() = default;
    // Drives line `line` (request order) high or low.
    virtual void set(std::size_t line, bool high) = 0;
    virtual std::string describe() const = 0;
};

}  // namespace avatarbooth
