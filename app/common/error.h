// Errors the booth reports to a person: what went wrong, and where (file, line, field).
#pragma once

#include <stdexcept>
#include <string>

namespace avatarbooth {

// Why a fit or a command failed; the CLI maps each kind to its own exit code (see app/cli/exit_codes.h).
enum class ErrorKind {
    BadInput,     // an input file is missing, unreadable, corrupt or not what it claims to be
    NoFace,       // the photo was read but no face (or no head) was found in it
    Mismatch,     // the two photos do not belong together (size, view direction)
    BadConfig,    // a configuration file or option has a wrong value
    Output,       // the output could not be written (disk full, permissions)
    Device,       // a camera, button line or display is missing, busy or went away
    Internal,     // a bug or an unexpected library failure
};

class BoothError : public std::runtime_error {
public:
    BoothError(ErrorKind kind, std::string where, const std::string& what)
        : std::runtime_error(where.empty() ? what : where + ": " + what), kind_(kind), where_(std::move(where)),
          message_(what) {}

    ErrorKind kind() const { return kind_; }
    // The file (and line/field where known) the error is about; empty when it concerns no file.
    const std::string& where() const { return where_; }
    // What went wrong, without the where (what() is "where: message").
    const std::string& message() const { return message_; }

private:
    ErrorKind kind_;
    std::string where_;
    std::string message_;
};

}  // namespace avatarbooth
