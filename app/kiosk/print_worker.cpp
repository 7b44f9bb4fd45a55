// The kiosk's printer (see print_worker.h).
#include "kiosk/print_worker.h"

#include "common/atomic_output.h"
#include "kiosk/thread_priority.h"
#include "print/card.h"

#include <spdlog/fmt/fmt.h>

namespace avatarbooth {

namespace {
using Seconds = std::chrono::duration<double>;

// What the job's state means for the operator: held, stopped, canceled and aborted jobs need them.
bool jobProblem(const JobState& j) {
    using S = JobState::State;
    return j.state == S::Held || j.state == S::Stopped || j.state == S::Canceled || j.state == S::Aborted;
}
}  // namespace

PrintWorker::PrintWorker(const PrintSettings& settings, KioskQueue& queue, std::chrono::milliseconds poll,
                         int niceness)
    : settings_(settings), queue_(queue), poll_(poll), niceness_(niceness) {
    thread_ = std::thread([this] { run(); });
}

PrintWorker::~PrintWorker() {
    {
        std::lock_guard lock(mutex_);
        quit_ = true;
        cards_.clear();
    }
    wake_.notify_all();
    thread_.join();
}

void PrintWorker::print(PrintCard card) {
    {
        std::lock_guard lock(mutex_);
        cards_.push_back(std::move(card));
    }
    wake_.notify_all();
}

bool PrintWorker::waitSent(std::chrono::milliseconds limit) {
    std::unique_lock lock(mutex_);
    return sent_.wait_for(lock, limit, [&] { return quit_ || (cards_.empty() && !busy_); });
}

void PrintWorker::run() {
    lowerThisThreadsPriority(niceness_);
    auto nextPoll = std::chrono::steady_clock::now();
    for (;;) {
        PrintCard card;
        bool have = false;
        {
            std::unique_lock lock(mutex_);
            wake_.wait_until(lock, nextPoll, [&] { return quit_ || !cards_.empty(); });
            if (quit_) return;
            if (!cards_.empty()) {
                card = std::move(cards_.front());
                cards_.pop_front();
                busy_ = have = true;
            }
        }
        if (have) {
            send(card);
            std::lock_guard lock(mutex_);
            busy_ = false;
            sent_.notify_all();
        }
        if (std::chrono::steady_clock::now() >= nextPoll) {
            watch();
            nextPoll = std::chrono::steady_clock::now() + poll_;
        }
    }
}

// The card made, written into the session (card.pdf, which the visitor's page can offer too) and sent.
void PrintWorker::send(const PrintCard& card) {
    const auto t0 = std::chrono::steady_clock::now();
    try {
        const std::string pdf = renderCardPdf(readCardContent(card.keptFolder, card.code, card.shareUrl, settings_),
                                              settings_);
        const std::filesystem::path file = card.keptFolder / "card.pdf";
        writeFileAtomically(file, pdf);
        const double made = Seconds(std::chrono::steady_clock::now() - t0).count();
        const std::string media = !settings_.media.empty()
                                      ? settings_.media
                                      : fmt::format("Custom.{:g}x{:g}mm", settings_.widthMm, settings_.heightMm);
        const int id = submitPdf(settings_.queue, file.string(), "avatarbooth " + card.code, settings_.copies, media);
        watched_.push_back({id, card.code, ""});
        tell(fmt::format("card {} sent (job {}, {} KB, made in {:.2f} s, sent in {:.2f} s)", card.code, id,
                         pdf.size() / 1024, made, Seconds(std::chrono::steady_clock::now() - t0).count() - made),
             false);
    } catch (const std::exception& e) {
        tell(fmt::format("card {} not printed: {}", card.code, e.what()), true);
    }
}

// The queue's and each job's state, told when they change; finished jobs are no longer watched.
void PrintWorker::watch() {
    const QueueState q = queryQueue(settings_.queue);
    const std::string queueLine = "queue " + (q.queue.empty() ? std::string("(default)") : q.queue) + ": " + q.describe();
    if (queueLine != lastQueue_) {
        // The first state is told only when something is wrong; later changes always (a problem clearing too).
        if (!lastQueue_.empty() || q.problem()) tell(queueLine, q.problem());
        lastQueue_ = queueLine;
    }
    for (auto it = watched_.begin(); it != watched_.end();) {
        const JobState j = queryJob(it->id);
        const std::string line = fmt::format("card {} (job {}): {}", it->code, it->id, j.describe());
        if (line != it->last) {
            tell(line, jobProblem(j));
            it->last = line;
        }
        it = j.finished() ? watched_.erase(it) : it + 1;
    }
}

void PrintWorker::tell(std::string line, bool problem) { queue_.post(PrintStatus{std::move(line), problem}); }

}  // namespace avatarbooth
