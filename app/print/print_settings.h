// [print]: the printed card (issue 23), off by default. What is printed (print/card.h) and where it goes (a CUPS
// queue, print/cups_queue.h).
#pragma once

#include <string>

namespace avatarbooth {

struct PrintSettings {
    // Keep prints a card only when this is true: printing is opt-in (paper, ink and a printer to look after).
    bool enabled = false;
    // The CUPS queue (`lpstat -p` lists them); "" = the CUPS server's default destination.
    std::string queue;
    // The card's size in millimetres (the default is the 100 x 148 mm postcard that dye-sublimation photo printers
    // use) and the resolution its pictures are placed at.
    double widthMm = 100.0;
    double heightMm = 148.0;
    int dpi = 300;
    // The printer's own name for the paper ("Postcard", "w284h420"); "" = the card's size asked for as a custom
    // size ("Custom.100x148mm"), which CUPS matches to the printer's nearest paper.
    std::string media;
    // The visitor's front photo on the card too (personal data on paper: off unless the operator wants it).
    bool frontPhoto = false;
    // The line across the card's top (the event's name, say).
    std::string title = "My 3-D avatar";
    // Cards per kept session.
    int copies = 1;
};

}  // namespace avatarbooth
