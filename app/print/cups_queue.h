// A CUPS print queue through libcups (Debian libcups2): its state, sending it a PDF, and a job's state. The CUPS
// server is the one libcups finds (the CUPS_SERVER environment variable, ~/.cups/client.conf,
// /etc/cups/client.conf, else the local scheduler's socket); every call gives up after a few seconds when the
// server does not answer, so a caller is never held longer than that.
#pragma once

#include <string>
#include <vector>

namespace avatarbooth {

// What the queue says about itself (IPP Get-Printer-Attributes).
struct QueueState {
    std::string queue;  // the name asked for, or the default destination's name
    std::string error;  // the server could not be asked, or has no such queue: nothing below is known
    bool accepting = false;       // printer-is-accepting-jobs (cupsreject turns it off)
    bool stopped = false;         // printer-state is stopped (cupsdisable, or the driver stopped it on an error)
    bool processing = false;      // printing now
    std::vector<std::string> reasons;  // printer-state-reasons other than "none" ("paused", "media-empty-error")
    std::string message;               // printer-state-message, the driver's own words

    bool found() const { return error.empty(); }
    // Something an operator has to act on: no such queue or no server, not accepting, stopped, out of paper.
    bool problem() const;
    // One line for the operator: "idle, accepting jobs", "stopped (paused), not accepting jobs: out of paper".
    std::string describe() const;
};

// The state of `queue` ("" = the server's default destination). Never throws: a failure is in `error`.
QueueState queryQueue(const std::string& queue);

// What CUPS says of one job (IPP Get-Job-Attributes).
struct JobState {
    enum class State { Unknown, Pending, Held, Processing, Stopped, Canceled, Aborted, Completed };
    State state = State::Unknown;
    std::vector<std::string> reasons;  // job-state-reasons ("job-hold-until-specified", "printer-stopped")
    std::string message;               // job-printer-state-message / the error
    // Completed, canceled or aborted: nothing more will happen to it.
    bool finished() const { return state == State::Canceled || state == State::Aborted || state == State::Completed; }
    std::string describe() const;  // "completed", "held (job-hold-until-specified)", "aborted: ..."
};

// The state of job `id` (JobState::Unknown with `message` when the server cannot be asked). Never throws.
JobState queryJob(int id);

// Sends `pdf` (a file) to `queue` ("" = the default) as one job named `title`, `copies` times, asking for
// `media` ("" = the printer's default paper). Returns the job's id; throws BoothError(Device) with the server's
// reason when the job is refused (no such queue, not accepting jobs, no server).
int submitPdf(const std::string& queue, const std::string& pdf, const std::string& title, int copies,
              const std::string& media);

}  // namespace avatarbooth
