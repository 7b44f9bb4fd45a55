// Prints the card of each kept session (print/card.h) on a thread of its own and then watches the queue and the
// job (print/cups_queue.h), posting what an operator should know to the kiosk's queue as PrintStatus: the booth
// never waits for a printer. A printer stopped, out of paper, a job held, failed or canceled is told once when it
// happens (and again when it clears); the visitor flow goes on either way.
#pragma once

#include "kiosk/kiosk_messages.h"
#include "print/cups_queue.h"
#include "print/print_settings.h"

#include <chrono>
#include <condition_variable>
#include <deque>
#include <filesystem>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace avatarbooth {

struct PrintCard {
    std::filesystem::path keptFolder;  // card.pdf is written there
    std::string code;
    std::string shareUrl;  // "" = no QR code
};

class PrintWorker {
public:
    // `poll`: how often the queue and the jobs in flight are asked about (each ask is one short IPP request).
    PrintWorker(const PrintSettings& settings, KioskQueue& queue,
                std::chrono::milliseconds poll = std::chrono::seconds(2), int niceness = 5);
    // Finishes the card in hand (a half-written card.pdf is never left: it is written atomically); jobs already
    // sent stay with CUPS.
    ~PrintWorker();
    PrintWorker(const PrintWorker&) = delete;
    PrintWorker& operator=(const PrintWorker&) = delete;

    void print(PrintCard card);
    // Blocks until every card asked for has been made and sent (or refused), at most `limit`; true when so.
    bool waitSent(std::chrono::milliseconds limit);

private:
    struct Watched {
        int id;
        std::string code;
        std::string last;  // the last state told
    };
    void run();
    void send(const PrintCard& card);
    void watch();
    void tell(std::string line, bool problem);

    const PrintSettings settings_;
    KioskQueue& queue_;
    const std::chrono::milliseconds poll_;
    const int niceness_;
    std::mutex mutex_;
    std::condition_variable wake_, sent_;
    std::deque<PrintCard> cards_;
    bool busy_ = false;
    bool quit_ = false;
    std::vector<Watched> watched_;  // the worker thread's own
    std::string lastQueue_;         // the queue's last state told
    std::thread thread_;            // last: starts once everything above exists
};

}  // namespace avatarbooth
