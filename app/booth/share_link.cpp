// Share tokens, listen addresses and page URLs (see share_link.h).
#include "booth/share_link.h"

#include "common/error.h"

#include <nlohmann/json.hpp>

#include <sys/random.h>

#include <cerrno>
#include <charconv>
#include <cstring>
#include <fstream>

namespace avatarbooth {

std::string makeShareToken() {
    unsigned char bytes[kShareTokenBytes];
    std::size_t got = 0;
    while (got < sizeof bytes) {
        // Blocks only until the kernel's pool is first initialised (early boot); never returns weaker bytes.
        const ssize_t n = ::getrandom(bytes + got, sizeof bytes - got, 0);
        if (n < 0) {
            if (errno == EINTR) continue;
            throw BoothError(ErrorKind::Internal, "getrandom", std::string("no random bytes: ") + std::strerror(errno));
        }
        got += static_cast<std::size_t>(n);
    }
    static constexpr char kHex[] = "0123456789abcdef";
    std::string token;
    token.reserve(kShareTokenLength);
    for (const unsigned char b : bytes) {
        token.push_back(kHex[b >> 4]);
        token.push_back(kHex[b & 15]);
    }
    return token;
}

bool isShareToken(std::string_view text) {
    if (text.size() != kShareTokenLength) return false;
    for (const char c : text)
        if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
    return true;
}

std::optional<ListenAddress> parseListenAddress(std::string_view text, bool anyPort) {
    const std::size_t colon = text.rfind(':');
    if (colon == std::string_view::npos || colon == 0 || colon + 1 >= text.size()) return std::nullopt;
    std::string_view host = text.substr(0, colon);
    const std::string_view portText = text.substr(colon + 1);
    if (host.front() == '[') {
        if (host.size() < 3 || host.back() != ']') return std::nullopt;
        host = host.substr(1, host.size() - 2);
    } else if (host.find(':') != std::string_view::npos) {
        return std::nullopt;  // an IPv6 address must be in brackets, or its last group would read as the port
    }
    for (const char c : host)
        if (c == ' ' || c == '/' || c == '[' || c == ']') return std::nullopt;
    int port = 0;
    const auto [end, ec] = std::from_chars(portText.data(), portText.data() + portText.size(), port);
    if (ec != std::errc{} || end != portText.data() + portText.size() || port < (anyPort ? 0 : 1) || port > 65535) return std::nullopt;
    return ListenAddress{std::string(host), port};
}

std::string shareBaseUrl(const ShareSettings& settings) {
    std::string base = settings.baseUrl;
    if (base.empty()) {
        const bool tls = !settings.tlsCertificate.empty();
        const auto address = parseListenAddress(settings.listen);
        if (!address) return "";
        const bool ipv6 = address->host.find(':') != std::string::npos;
        base = std::string(tls ? "https://" : "http://") + (ipv6 ? "[" + address->host + "]" : address->host);
        if (address->port != (tls ? 443 : 80)) base += ":" + std::to_string(address->port);
    }
    while (!base.empty() && base.back() == '/') base.pop_back();
    return base;
}

std::string sharePageUrl(const ShareSettings& settings, std::string_view token) {
    return shareBaseUrl(settings) + "/s/" + std::string(token);
}

std::optional<std::string> readShareToken(const std::filesystem::path& sessionFolder) {
    std::ifstream in(sessionFolder / "session.json");
    if (!in) return std::nullopt;
    try {
        const auto j = nlohmann::json::parse(in);
        const auto it = j.find("share_token");
        if (it == j.end() || !it->is_string()) return std::nullopt;
        std::string token = it->get<std::string>();
        if (!isShareToken(token)) return std::nullopt;
        return token;
    } catch (const std::exception&) {
        return std::nullopt;  // a damaged session.json: the session has no page
    }
}

}  // namespace avatarbooth
