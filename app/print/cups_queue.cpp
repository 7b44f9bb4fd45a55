// CUPS through libcups's own IPP requests (see cups_queue.h).
#include "print/cups_queue.h"

#include "common/error.h"

#include <cups/cups.h>

#include <algorithm>
#include <memory>

namespace avatarbooth {
namespace {

constexpr int kConnectMs = 3000;     // connecting to the scheduler
constexpr double kRequestS = 5.0;    // waiting for one answer

// Gives up on a request when the server has not answered within kRequestS (httpSetTimeout's callback: 0 = stop).
int giveUp(http_t*, void*) { return 0; }

using Connection = std::unique_ptr<http_t, decltype(&httpClose)>;
using Message = std::unique_ptr<ipp_t, decltype(&ippDelete)>;

// A connection to the scheduler libcups is configured for; null with `error` set when there is none.
Connection connect(std::string& error) {
    Connection http(httpConnect2(cupsServer(), ippPort(), nullptr, AF_UNSPEC, cupsEncryption(), 1, kConnectMs, nullptr),
                    httpClose);
    if (!http) error = std::string("no CUPS scheduler at ") + cupsServer() + " (is cups running?)";
    else httpSetTimeout(http.get(), kRequestS, giveUp, nullptr);
    return http;
}

// The queue's name: `queue` itself, or the default destination's.
std::string resolve(http_t* http, const std::string& queue, std::string& error) {
    if (!queue.empty()) return queue;
    cups_dest_t* dest = cupsGetNamedDest(http, nullptr, nullptr);
    if (!dest) {
        error = "no default print queue on the CUPS server (set [print] queue)";
        return {};
    }
    std::string name = dest->name;
    cupsFreeDests(1, dest);
    return name;
}

std::string printerUri(const std::string& queue) {
    char uri[HTTP_MAX_URI];
    httpAssembleURIf(HTTP_URI_CODING_ALL, uri, sizeof uri, "ipp", nullptr, "localhost", 0, "/printers/%s",
                     queue.c_str());
    return uri;
}

std::vector<std::string> strings(ipp_t* answer, const char* name) {
    std::vector<std::string> out;
    if (ipp_attribute_t* a = ippFindAttribute(answer, name, IPP_TAG_KEYWORD)) {
        for (int i = 0; i < ippGetCount(a); ++i) {
            const char* s = ippGetString(a, i, nullptr);
            if (s && std::string(s) != "none") out.emplace_back(s);
        }
    }
    return out;
}

std::string text(ipp_t* answer, const char* name) {
    ipp_attribute_t* a = ippFindAttribute(answer, name, IPP_TAG_ZERO);
    const char* s = a ? ippGetString(a, 0, nullptr) : nullptr;
    return s ? s : "";
}

bool hasPrefix(const std::vector<std::string>& reasons, const std::string& prefix) {
    return std::any_of(reasons.begin(), reasons.end(), [&](const std::string& r) { return r.rfind(prefix, 0) == 0; });
}

std::string joined(const std::vector<std::string>& items) {
    std::string s;
    for (const auto& i : items) s += (s.empty() ? "" : ", ") + i;
    return s;
}

}  // namespace

bool QueueState::problem() const {
    return !found() || !accepting || stopped || hasPrefix(reasons, "media-empty") || hasPrefix(reasons, "media-needed") ||
           std::any_of(reasons.begin(), reasons.end(), [](const std::string& r) {
               return r.size() > 6 && r.compare(r.size() - 6, 6, "-error") == 0;
           });
}

std::string QueueState::describe() const {
    if (!found()) return error;
    std::string s = stopped ? "stopped" : processing ? "printing" : "idle";
    s += accepting ? ", accepting jobs" : ", not accepting jobs";
    // What an operator must do first, in words; the reasons themselves follow for the log and the curious.
    if (hasPrefix(reasons, "media-empty") || hasPrefix(reasons, "media-needed")) s += ": out of paper";
    else if (hasPrefix(reasons, "media-jam")) s += ": paper jam";
    if (!reasons.empty()) s += " (" + joined(reasons) + ")";
    if (!message.empty()) s += " \"" + message + "\"";
    return s;
}

QueueState queryQueue(const std::string& queue) {
    QueueState q;
    q.queue = queue;
    Connection http = connect(q.error);
    if (!http) return q;
    q.queue = resolve(http.get(), queue, q.error);
    if (q.queue.empty()) return q;
    ipp_t* request = ippNewRequest(IPP_OP_GET_PRINTER_ATTRIBUTES);
    ippAddString(request, IPP_TAG_OPERATION, IPP_TAG_URI, "printer-uri", nullptr, printerUri(q.queue).c_str());
    static const char* const kWanted[] = {"printer-state", "printer-state-reasons", "printer-is-accepting-jobs",
                                          "printer-state-message"};
    ippAddStrings(request, IPP_TAG_OPERATION, IPP_TAG_KEYWORD, "requested-attributes", 4, nullptr, kWanted);
    Message answer(cupsDoRequest(http.get(), request, "/"), ippDelete);  // cupsDoRequest frees the request
    if (!answer || cupsLastError() > IPP_STATUS_OK_CONFLICTING) {
        q.error = cupsLastError() == IPP_STATUS_ERROR_NOT_FOUND
                      ? "no print queue \"" + q.queue + "\" on the CUPS server (lpstat -p lists them)"
                      : "print queue \"" + q.queue + "\": " + cupsLastErrorString();
        return q;
    }
    ipp_attribute_t* state = ippFindAttribute(answer.get(), "printer-state", IPP_TAG_ENUM);
    const int s = state ? ippGetInteger(state, 0) : IPP_PSTATE_IDLE;
    q.stopped = s == IPP_PSTATE_STOPPED;
    q.processing = s == IPP_PSTATE_PROCESSING;
    ipp_attribute_t* accepting = ippFindAttribute(answer.get(), "printer-is-accepting-jobs", IPP_TAG_BOOLEAN);
    q.accepting = accepting && ippGetBoolean(accepting, 0);
    q.reasons = strings(answer.get(), "printer-state-reasons");
    q.message = text(answer.get(), "printer-state-message");
    return q;
}

std::string JobState::describe() const {
    std::string s;
    switch (state) {
        case State::Unknown: s = "unknown"; break;
        case State::Pending: s = "waiting"; break;
        case State::Held: s = "held"; break;
        case State::Processing: s = "printing"; break;
        case State::Stopped: s = "stopped"; break;
        case State::Canceled: s = "canceled"; break;
        case State::Aborted: s = "failed (aborted)"; break;
        case State::Completed: s = "printed"; break;
    }
    std::vector<std::string> shown;
    for (const auto& r : reasons)
        if (r != "job-completed-successfully" && r != "job-printing" && r != "job-incoming" &&
            r != "processing-to-stop-point") shown.push_back(r);
    if (!shown.empty()) s += " (" + joined(shown) + ")";
    if (!message.empty()) s += ": " + message;
    return s;
}

JobState queryJob(int id) {
    JobState j;
    Connection http = connect(j.message);
    if (!http) return j;
    ipp_t* request = ippNewRequest(IPP_OP_GET_JOB_ATTRIBUTES);
    char uri[HTTP_MAX_URI];
    httpAssembleURIf(HTTP_URI_CODING_ALL, uri, sizeof uri, "ipp", nullptr, "localhost", 0, "/jobs/%d", id);
    ippAddString(request, IPP_TAG_OPERATION, IPP_TAG_URI, "job-uri", nullptr, uri);
    static const char* const kWanted[] = {"job-state", "job-state-reasons", "job-printer-state-message"};
    ippAddStrings(request, IPP_TAG_OPERATION, IPP_TAG_KEYWORD, "requested-attributes", 3, nullptr, kWanted);
    Message answer(cupsDoRequest(http.get(), request, "/"), ippDelete);
    if (!answer || cupsLastError() > IPP_STATUS_OK_CONFLICTING) {
        j.message = cupsLastErrorString();
        return j;
    }
    ipp_attribute_t* state = ippFindAttribute(answer.get(), "job-state", IPP_TAG_ENUM);
    switch (state ? ippGetInteger(state, 0) : 0) {
        case IPP_JSTATE_PENDING: j.state = JobState::State::Pending; break;
        case IPP_JSTATE_HELD: j.state = JobState::State::Held; break;
        case IPP_JSTATE_PROCESSING: j.state = JobState::State::Processing; break;
        case IPP_JSTATE_STOPPED: j.state = JobState::State::Stopped; break;
        case IPP_JSTATE_CANCELED: j.state = JobState::State::Canceled; break;
        case IPP_JSTATE_ABORTED: j.state = JobState::State::Aborted; break;
        case IPP_JSTATE_COMPLETED: j.state = JobState::State::Completed; break;
        default: break;
    }
    j.reasons = strings(answer.get(), "job-state-reasons");
    j.message = text(answer.get(), "job-printer-state-message");
    return j;
}

int submitPdf(const std::string& queue, const std::string& pdf, const std::string& title, int copies,
              const std::string& media) {
    std::string error;
    Connection http = connect(error);
    if (!http) throw BoothError(ErrorKind::Device, "print", error);
    const std::string name = resolve(http.get(), queue, error);
    if (name.empty()) throw BoothError(ErrorKind::Device, "print", error);
    cups_option_t* options = nullptr;
    int count = 0;
    count = cupsAddOption("copies", std::to_string(std::max(1, copies)).c_str(), count, &options);
    if (!media.empty()) count = cupsAddOption("media", media.c_str(), count, &options);
    const int id = cupsPrintFile2(http.get(), name.c_str(), pdf.c_str(), title.c_str(), count, options);
    cupsFreeOptions(count, options);
    if (id <= 0)
        throw BoothError(ErrorKind::Device, "print queue \"" + name + "\"", cupsLastErrorString());
    return id;
}

}  // namespace avatarbooth
