// The printed card (issue 23) against a real CUPS: each test of PrintCups starts its own `cupsd` (Debian
// cups-daemon) on a socket in its scratch folder with a cups-pdf queue (printer-driver-cups-pdf) writing into that
// folder, prints a kept session's card through the kiosk's PrintWorker and reads what comes out with poppler-utils
// (pdfinfo, pdftotext, pdftoppm) and zbarimg: one 100 x 148 mm page, the code in its text, the QR code scanning
// back to the visitor's page, the three styles' pixels where the layout puts them. A disabled queue (cupsdisable)
// and a rejecting one (cupsreject) are reported as problems while the worker never blocks its caller. cupsd and
// cups-pdf need root: without it (or without the packages, which tests/setup.sh installs) the tests skip and say so.
// PrintCard.* lay the card out without CUPS.
#include "booth/session_store.h"
#include "booth/share_link.h"
#include "common/atomic_output.h"
#include "common/image_io.h"
#include "kiosk/print_worker.h"
#include "print/card.h"
#include "print/cups_queue.h"
#include "share/share_site.h"
#include "cups_server.h"
#include "test_paths.h"

#include <gtest/gtest.h>

#include <cups/cups.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <csignal>
#include <cstdio>
#include <fstream>
#include <regex>
#include <thread>

#include <sys/wait.h>
#include <unistd.h>

using namespace avatarbooth;
using namespace avatarbooth::test;
namespace fs = std::filesystem;
using Seconds = std::chrono::duration<double>;

namespace {


// Pure colours for the three styles, so that the printed pixels say which picture landed where.
const cv::Scalar kPhotoColour(40, 40, 220), kCharacterColour(40, 200, 40), kToonColour(220, 60, 40);  // BGR

// A session kept through the real store, its pictures stand-ins: a disc of one colour per style on grey.
struct Kept {
    std::string code, url;
    fs::path folder;
};
Kept keepSession(const fs::path& sessions) {
    SessionStoreSettings settings;
    settings.directory = sessions;
    SessionStore store(settings);
    const fs::path pending = store.pendingPath();
    {
        StagedDirectory staged(pending, "fit.json");
        const auto disc = [&](const fs::path& file, const cv::Scalar& colour, cv::Size size) {
            cv::Mat image(size, CV_8UC3, cv::Scalar(128, 128, 128));
            cv::circle(image, {size.width / 2, size.height / 2}, size.width * 2 / 5, colour, cv::FILLED);
            fs::create_directories(file.parent_path());
            writeFileAtomically(file, encodeImage(image, ".png"));
        };
        disc(staged.staging() / "preview_three_quarter.png", kPhotoColour, {512, 512});
        disc(staged.staging() / "preview_character.png", kCharacterColour, {512, 512});
        disc(staged.staging() / "toon" / "turntable_000.png", kToonColour, {400, 440});
        writeFileAtomically(staged.staging() / "fit.json", "{}");
        staged.commit();
    }
    Kept k;
    k.code = store.keep(pending, std::chrono::system_clock::now());
    k.folder = *store.find(k.code);
    ShareSettings share;
    share.baseUrl = "http://10.42.0.1";
    k.url = sharePageUrl(share, readShareToken(k.folder).value());
    return k;
}

// What a PDF holds: its pages and page size (pdfinfo), its text (pdftotext), its first page as pixels at 100 dpi
// (pdftoppm) and what zbarimg reads off them.
struct PdfLook {
    int pages = 0;
    double widthPt = 0, heightPt = 0;
    std::string text, qr;
    cv::Mat pixels;
};
PdfLook look(const fs::path& pdf) {
    PdfLook l;
    const std::string info = run("pdfinfo '" + pdf.string() + "'").out;
    std::smatch m;
    if (std::regex_search(info, m, std::regex(R"(Pages:\s+(\d+))"))) l.pages = std::stoi(m[1]);
    if (std::regex_search(info, m, std::regex(R"(Page size:\s+([\d.]+) x ([\d.]+) pts)"))) {
        l.widthPt = std::stod(m[1]);
        l.heightPt = std::stod(m[2]);
    }
    l.text = run("pdftotext '" + pdf.string() + "' -").out;
    const fs::path png = pdf.parent_path() / (pdf.stem().string() + "_page");
    run("pdftoppm -r 100 -png -singlefile '" + pdf.string() + "' '" + png.string() + "'");
    l.pixels = cv::imread(png.string() + ".png");
    l.qr = run("zbarimg --raw -q '" + png.string() + ".png'", false).out;
    while (!l.qr.empty() && (l.qr.back() == '\n' || l.qr.back() == '\r')) l.qr.pop_back();
    return l;
}

// How much of the page is close to `colour` in the horizontal band [top, bottom) (fractions of the height).
double share(const cv::Mat& page, const cv::Scalar& colour, double top, double bottom) {
    const cv::Mat band = page.rowRange(static_cast<int>(top * page.rows), static_cast<int>(bottom * page.rows));
    cv::Mat mask;
    cv::inRange(band, colour - cv::Scalar(40, 40, 40), colour + cv::Scalar(40, 40, 40), mask);
    return static_cast<double>(cv::countNonZero(mask)) / static_cast<double>(mask.total());
}

// The card's checks, for a PDF made here or one that came out of CUPS (whose text Ghostscript turns into
// outlines that pdftotext cannot read: the code is checked there by comparing the pixels with the card sent).
void expectCard(const fs::path& pdf, const Kept& kept, bool hasText = true) {
    const PdfLook l = look(pdf);
    EXPECT_EQ(l.pages, 1);
    EXPECT_NEAR(l.widthPt, 100.0 / 25.4 * 72.0, 1.0) << "100 mm wide";
    EXPECT_NEAR(l.heightPt, 148.0 / 25.4 * 72.0, 1.0) << "148 mm high";
    if (hasText) {
        EXPECT_NE(l.text.find(kept.code), std::string::npos) << "the code is in the card's text: " << l.text;
    }
    EXPECT_EQ(l.qr, kept.url) << "the QR code scans back to the visitor's page";
    ASSERT_FALSE(l.pixels.empty());
    // The photo style large in the upper half, the character and the toon in the row under it, none of them in
    // the code's band at the bottom.
    EXPECT_GT(share(l.pixels, kPhotoColour, 0.1, 0.5), 0.15);
    EXPECT_GT(share(l.pixels, kCharacterColour, 0.5, 0.8), 0.03);
    EXPECT_GT(share(l.pixels, kToonColour, 0.5, 0.8), 0.03);
    EXPECT_LT(share(l.pixels, kPhotoColour, 0.8, 1.0) + share(l.pixels, kToonColour, 0.8, 1.0), 0.001);
}

// How far two renders of a card are apart (mean absolute grey levels), at the best of the small shifts, over the
// whole card and over the code's box (the band's left part, under the pictures).
struct Difference {
    double whole = 255, code = 255;
};
Difference difference(const cv::Mat& a, const cv::Mat& b) {
    Difference best;
    const int m = 2;
    const cv::Rect common(0, 0, std::min(a.cols, b.cols), std::min(a.rows, b.rows));
    const cv::Rect inner(m, m, common.width - 2 * m, common.height - 2 * m);
    const cv::Rect code(0, inner.height * 4 / 5, inner.width * 3 / 5, inner.height / 5);
    for (int dy = -m; dy <= m; ++dy)
        for (int dx = -m; dx <= m; ++dx) {
            cv::Mat d;
            cv::absdiff(a(inner), b(inner + cv::Point(dx, dy)), d);
            const double whole = cv::mean(d)[0];
            if (whole < best.whole) best = {whole, cv::mean(d(code))[0]};
        }
    return best;
}

bool havePoppler() { return have("pdfinfo") && have("pdftoppm") && have("pdftotext") && have("zbarimg"); }


// PrintStatus messages from the worker until one matches `pattern` or `limit` passes; all of them for the record.
struct Heard {
    bool found = false;
    std::vector<PrintStatus> all;
    double seconds = 0;
};
Heard waitFor(KioskQueue& queue, const std::string& pattern, Seconds limit) {
    Heard h;
    const auto t0 = std::chrono::steady_clock::now();
    const std::regex re(pattern);
    while (std::chrono::steady_clock::now() - t0 < limit) {
        auto m = queue.waitUntil(std::chrono::steady_clock::now() + std::chrono::milliseconds(100));
        if (!m) continue;
        if (const auto* s = std::get_if<PrintStatus>(&*m)) {
            h.all.push_back(*s);
            if (std::regex_search(s->line, re)) {
                h.found = true;
                break;
            }
        }
    }
    h.seconds = Seconds(std::chrono::steady_clock::now() - t0).count();
    return h;
}
std::string lines(const Heard& h) {
    std::string s;
    for (const auto& m : h.all) s += (m.problem ? "  [problem] " : "  ") + m.line + "\n";
    return s;
}

PrintSettings cardSettings(const std::string& queue) {
    PrintSettings p;
    p.enabled = true;
    p.queue = queue;
    p.title = "Avatar booth test";
    return p;
}

}  // namespace

TEST(PrintCard, LaidOutOnOne100x148PageWithCodeQrAndTheThreeStyles) {
    if (!havePoppler()) GTEST_SKIP() << "poppler-utils or zbar-tools is missing (tests/setup.sh installs them)";
    const fs::path dir = test::scratchDir("print_card_layout");
    const Kept kept = keepSession(dir / "sessions");
    PrintSettings settings = cardSettings("");
    const auto t0 = std::chrono::steady_clock::now();
    const std::string pdf = renderCardPdf(readCardContent(kept.folder, kept.code, kept.url, settings), settings);
    std::printf("card laid out: %zu KB of PDF in %.3f s\n", pdf.size() / 1024, Seconds(std::chrono::steady_clock::now() - t0).count());
    writeFileAtomically(dir / "card.pdf", pdf);
    expectCard(dir / "card.pdf", kept);
}

TEST(PrintCard, WithoutSharingTheCardHasTheCodeAndNoQrCode) {
    if (!havePoppler()) GTEST_SKIP() << "poppler-utils or zbar-tools is missing (tests/setup.sh installs them)";
    const fs::path dir = test::scratchDir("print_card_no_share");
    const Kept kept = keepSession(dir / "sessions");
    const PrintSettings settings = cardSettings("");
    writeFileAtomically(dir / "card.pdf", renderCardPdf(readCardContent(kept.folder, kept.code, "", settings), settings));
    const PdfLook l = look(dir / "card.pdf");
    EXPECT_NE(l.text.find(kept.code), std::string::npos);
    EXPECT_EQ(l.qr, "");
}

TEST(PrintCard, AFolderWithoutItsPreviewIsRefusedNamingTheFile) {
    const fs::path dir = test::scratchDir("print_card_incomplete");
    try {
        (void)readCardContent(dir, "ABCDEF", "", {});
        FAIL() << "no error";
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::BadInput);
        EXPECT_NE(std::string(e.what()).find("preview_three_quarter.png"), std::string::npos) << e.what();
    }
}

TEST(PrintCups, NoSchedulerIsReportedAtOnce) {
    setenv("CUPS_SERVER", "/nonexistent/avatarbooth/cups.sock", 1);
    cupsSetServer(nullptr);
    const auto t0 = std::chrono::steady_clock::now();
    const QueueState q = queryQueue("booth");
    unsetenv("CUPS_SERVER");
    cupsSetServer(nullptr);
    EXPECT_FALSE(q.found());
    EXPECT_TRUE(q.problem());
    EXPECT_NE(q.describe().find("no CUPS scheduler"), std::string::npos) << q.describe();
    EXPECT_LT(Seconds(std::chrono::steady_clock::now() - t0).count(), 5.0);
}

TEST(PrintCups, KeptSessionsCardComesOutOfCupsPdfAndItsTimeIsPrinted) {
    REQUIRE_CUPS();
    const fs::path dir = test::scratchDir("print_cups_card");
    CupsServer cups(dir / "cups");
    ASSERT_TRUE(cups.ok()) << cups.log();
    const QueueState q = queryQueue(cups.queue());
    EXPECT_TRUE(q.found()) << q.describe();
    EXPECT_TRUE(q.accepting);
    EXPECT_FALSE(q.problem()) << q.describe();
    const Kept kept = keepSession(dir / "sessions");

    KioskQueue messages;
    PrintWorker worker(cardSettings(cups.queue()), messages, std::chrono::milliseconds(200));
    const auto t0 = std::chrono::steady_clock::now();
    worker.print({kept.folder, kept.code, kept.url});
    const double returned = Seconds(std::chrono::steady_clock::now() - t0).count();
    const Heard h = waitFor(messages, ": printed", Seconds(60));
    ASSERT_TRUE(h.found) << lines(h) << cups.log();
    // cups-pdf names the file after the job's title.
    fs::path pdf;
    for (int i = 0; i < 50 && pdf.empty(); ++i) {
        for (const auto& e : fs::directory_iterator(cups.out()))
            if (e.path().extension() == ".pdf") pdf = e.path();
        if (pdf.empty()) std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    const double toPdf = Seconds(std::chrono::steady_clock::now() - t0).count();
    ASSERT_FALSE(pdf.empty()) << "cups-pdf wrote nothing\n" << lines(h) << cups.log();
    std::printf("card print time to PDF (keep -> cups-pdf's file, incl. card layout, CUPS filters, Ghostscript): "
                "%.2f s; print() returned in %.4f s\n%s",
                toPdf, returned, lines(h).c_str());
    ASSERT_TRUE(fs::is_regular_file(kept.folder / "card.pdf")) << "the card is kept in the session";
    expectCard(kept.folder / "card.pdf", kept);
    expectCard(pdf, kept, false);
    // The visitor's page offers the card it printed.
    ShareSettings share;
    share.enabled = true;
    SessionStoreSettings sessions;
    sessions.directory = dir / "sessions";
    ShareSite site(share, sessions, "");
    const std::string token = readShareToken(kept.folder).value();
    EXPECT_NE(site.answer("GET", "/s/" + token, std::chrono::system_clock::now()).body.find("/card.pdf"), std::string::npos);
    const ShareResponse card = site.answer("GET", "/s/" + token + "/card.pdf", std::chrono::system_clock::now());
    EXPECT_EQ(card.status, 200);
    EXPECT_EQ(card.contentType, "application/pdf");
    // What came out is the card that was sent, but for Ghostscript's resampling (the page up to a pixel or two away
    // and a row shorter): closer to it, in the code's box, than to the same card with another code.
    const PrintSettings settings = cardSettings(cups.queue());
    CardContent other = readCardContent(kept.folder, "XXXXXX", kept.url, settings);
    writeFileAtomically(dir / "other.pdf", renderCardPdf(other, settings));
    const cv::Mat sent = look(kept.folder / "card.pdf").pixels, printed = look(pdf).pixels,
                  wrong = look(dir / "other.pdf").pixels;
    const Difference same = difference(sent, printed), differs = difference(wrong, printed);
    std::printf("mean difference printed vs sent: %.2f grey levels (the code's box %.2f); vs another code's card "
                "%.2f (%.2f)\n", same.whole, same.code, differs.whole, differs.code);
    EXPECT_LT(same.whole, 6.0);
    EXPECT_LT(same.code, 0.5 * differs.code);
}

TEST(PrintCups, DisabledQueueIsReportedWhileTheBoothGoesOn) {
    REQUIRE_CUPS();
    const fs::path dir = test::scratchDir("print_cups_disabled");
    CupsServer cups(dir / "cups");
    ASSERT_TRUE(cups.ok()) << cups.log();
    // `avatarbooth check` reports the queue as the operator would see it, before and after it is disabled.
    const fs::path config = dir / "booth.toml";
    std::ofstream(config) << "[print]\nenabled = true\nqueue = \"" << cups.queue() << "\"\n";
    const auto checked = [&] {
        const std::string out = run(test::binary().string() + " check --config " + config.string(), false).out;
        std::smatch m;
        return std::regex_search(out, m, std::regex("(OK|WARN|FAIL) +print +([^\n]*)")) ? m[1].str() + " " + m[2].str()
                                                                                       : "no print line in:\n" + out;
    };
    const std::string before = checked();
    EXPECT_EQ(before.rfind("OK queue " + cups.queue() + ": idle, accepting jobs", 0), 0u) << before;
    ASSERT_TRUE(cups.command("/usr/sbin/cupsdisable -r 'out of cards' " + cups.queue()));
    const std::string after = checked();
    EXPECT_EQ(after.rfind("FAIL queue " + cups.queue() + ": stopped", 0), 0u) << after;
    EXPECT_NE(after.find("out of cards"), std::string::npos) << "the operator's reason: " << after;
    const QueueState q = queryQueue(cups.queue());
    EXPECT_TRUE(q.stopped);
    EXPECT_TRUE(q.problem());
    EXPECT_NE(q.describe().find("stopped"), std::string::npos) << q.describe();
    const Kept kept = keepSession(dir / "sessions");

    KioskQueue messages;
    PrintWorker worker(cardSettings(cups.queue()), messages, std::chrono::milliseconds(200));
    worker.print({kept.folder, kept.code, kept.url});
    EXPECT_TRUE(worker.waitSent(std::chrono::seconds(20))) << "the card is handed to CUPS, which queues it";
    const Heard h = waitFor(messages, "queue .*stopped", Seconds(20));
    EXPECT_TRUE(h.found) << lines(h);
    EXPECT_TRUE(!h.all.empty() && h.all.back().problem) << lines(h);
    // Enabled again, the waiting card comes out and the news says so.
    ASSERT_TRUE(cups.command("/usr/sbin/cupsenable " + cups.queue()));
    const Heard printed = waitFor(messages, ": printed", Seconds(60));
    EXPECT_TRUE(printed.found) << lines(printed) << cups.log();
}

TEST(PrintCups, RejectingQueueRefusesTheCardWithTheReason) {
    REQUIRE_CUPS();
    const fs::path dir = test::scratchDir("print_cups_rejecting");
    CupsServer cups(dir / "cups");
    ASSERT_TRUE(cups.ok()) << cups.log();
    ASSERT_TRUE(cups.command("/usr/sbin/cupsreject " + cups.queue()));
    const QueueState q = queryQueue(cups.queue());
    EXPECT_FALSE(q.accepting);
    EXPECT_TRUE(q.problem());
    const Kept kept = keepSession(dir / "sessions");

    KioskQueue messages;
    PrintWorker worker(cardSettings(cups.queue()), messages, std::chrono::milliseconds(200));
    worker.print({kept.folder, kept.code, kept.url});
    const Heard h = waitFor(messages, "not printed", Seconds(20));
    ASSERT_TRUE(h.found) << lines(h);
    const PrintStatus& refused = h.all.back();
    EXPECT_TRUE(refused.problem);
    EXPECT_NE(refused.line.find("not accepting"), std::string::npos) << refused.line;
    // A queue that does not exist is named as such.
    EXPECT_NE(queryQueue("no-such-queue").describe().find("no print queue"), std::string::npos);
}

TEST(PrintCups, HeldAndCanceledJobsAreReported) {
    REQUIRE_CUPS();
    const fs::path dir = test::scratchDir("print_cups_held");
    CupsServer cups(dir / "cups");
    ASSERT_TRUE(cups.ok()) << cups.log();
    const Kept kept = keepSession(dir / "sessions");
    const PrintSettings settings = cardSettings(cups.queue());
    writeFileAtomically(dir / "card.pdf", renderCardPdf(readCardContent(kept.folder, kept.code, kept.url, settings), settings));
    // A job held by the operator's hand (lp -H indefinite): what the worker's watch reports for such a job.
    const Ran lp = cups.output("lp -H indefinite -d " + cups.queue() + " '" + (dir / "card.pdf").string() + "'");
    std::smatch m;
    ASSERT_TRUE(std::regex_search(lp.out, m, std::regex(cups.queue() + "-(\\d+)"))) << lp.out;
    const JobState j = queryJob(std::stoi(m[1]));
    EXPECT_EQ(j.state, JobState::State::Held) << j.describe();
    EXPECT_FALSE(j.finished());
    EXPECT_NE(j.describe().find("held"), std::string::npos) << j.describe();
    // Canceled by the operator (cancel): finished, and told as such.
    ASSERT_TRUE(cups.command("/usr/bin/cancel " + cups.queue() + "-" + m[1].str()));
    const JobState canceled = queryJob(std::stoi(m[1]));
    EXPECT_EQ(canceled.state, JobState::State::Canceled) << canceled.describe();
    EXPECT_TRUE(canceled.finished());
    EXPECT_EQ(canceled.describe().rfind("canceled", 0), 0u) << canceled.describe();
}
