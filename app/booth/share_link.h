// "Take it home": what links a kept session to the visitor's own page (issue 23). Each kept session carries an
// unguessable token in its session.json; the page's URL is the public base URL + "/s/" + token, shown as a QR code
// on the thanks screen and served by `avatarbooth share` (app/share/). Off unless the operator turns it on.
//
// The token is 128 bits from the kernel's random source (getrandom(2)), written as 32 lower-case hex digits: it is
// the only key to the page (the short code is typed by the operator, never accepted by the page), so it must not
// be guessable from earlier tokens or from the clock, which a seeded PRNG would allow.
#pragma once

#include <chrono>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace avatarbooth {

struct ShareSettings {
    // Nothing listens unless this is true: the visitor's page is opt-in.
    bool enabled = false;
    // Where `avatarbooth share` listens, "ADDRESS:PORT" (the booth's own hotspot: NetworkManager's 10.42.0.1).
    std::string listen = "10.42.0.1:80";
    // The URL the visitor's phone reaches the server by, without a trailing slash; "" = http(s)://<listen>.
    std::string baseUrl;
    // A page answers for this long after its session was kept (never longer than the session is retained).
    std::chrono::seconds pageLifetime = std::chrono::hours(24 * 7);
    // The page offers avatar.glb, avatar.usdz and the preview image for download (the AR view needs the first two
    // whether or not they are offered as downloads).
    bool offerDownloads = true;
    // The page also offers the visitor's two photos while they are kept (personal data: off unless the operator
    // allows it).
    bool offerPhotos = false;
    // TLS with the operator's certificate and key (PEM); both or neither. Empty: plain HTTP.
    std::filesystem::path tlsCertificate;
    std::filesystem::path tlsKey;
    // Requests answered at once (worker threads); further connections wait in a queue of the same length, then in
    // the kernel's backlog.
    int workers = 8;
    // A connection that sends nothing for this long is closed (also the limit between keep-alive requests).
    std::chrono::seconds readTimeout{5};
};

// Bytes in a token, and its length as text (hex).
inline constexpr std::size_t kShareTokenBytes = 16;
inline constexpr std::size_t kShareTokenLength = 2 * kShareTokenBytes;

// A fresh token: kShareTokenBytes from getrandom(2), as lower-case hex. Throws BoothError(Internal) when the kernel
// has no randomness to give (never with a seeded fallback).
std::string makeShareToken();

// Whether `text` has the shape of a token (kShareTokenLength lower-case hex digits). Says nothing about whether a
// session has it.
bool isShareToken(std::string_view text);

// "ADDRESS:PORT" split; nothing when it is not of that shape (the port 1-65535, or 0 = any free port when
// `anyPort` allows it; an IPv6 address in brackets).
struct ListenAddress {
    std::string host;
    int port = 0;
};
std::optional<ListenAddress> parseListenAddress(std::string_view text, bool anyPort = false);

// The base URL the visitor's phone uses: settings.baseUrl without a trailing slash, or built from `listen`
// (https when a certificate is configured; the port left out when it is the scheme's default).
std::string shareBaseUrl(const ShareSettings& settings);

// The page of the session with `token`.
std::string sharePageUrl(const ShareSettings& settings, std::string_view token);

// The token stored in a kept session's session.json; nothing when the file or the token is missing or malformed.
std::optional<std::string> readShareToken(const std::filesystem::path& sessionFolder);

}  // namespace avatarbooth
