// The printed card (issue 23): the visitor's three avatar styles, the session's short code and the QR code of the
// visitor's page, laid out for print with Cairo into a one-page PDF of the card's size (print_settings.h).
//
// Everything on it comes from the kept session folder (booth/session_folder.h), so a card can be made again from a
// session alone: the photo style is preview_three_quarter.png, the character preview_character.png, the toon the
// first frame of its turntable strip (toon/turntable_000.png), the front photo front.jpg while it is kept.
#pragma once

#include "print/print_settings.h"

#include <opencv2/core.hpp>

#include <filesystem>
#include <string>

namespace avatarbooth {

struct CardContent {
    std::string code;      // the session's short code (the operator's key to it)
    std::string shareUrl;  // the visitor's page; "" = no QR code on the card (sharing is off)
    // BGR pictures; an empty one is left off the card (a character that could not be made, a toon still drawing,
    // a front photo deleted by retention or not wanted).
    cv::Mat photoStyle, character, toon, frontPhoto;
};

// What a card of the kept session in `keptFolder` shows. Throws BoothError(BadInput) naming the file when the
// photo style's preview (which every complete session has) is missing or unreadable; the other pictures are
// optional.
CardContent readCardContent(const std::filesystem::path& keptFolder, const std::string& code,
                            const std::string& shareUrl, const PrintSettings& settings);

// The card as PDF bytes: one page of settings.widthMm x settings.heightMm, pictures placed at settings.dpi, text
// and the QR code as vectors (sharp at any printer's resolution). Throws BoothError(Internal) when Cairo fails.
std::string renderCardPdf(const CardContent& content, const PrintSettings& settings);

}  // namespace avatarbooth
