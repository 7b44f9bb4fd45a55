// The subcommands of the avatarbooth executable; each registers its options and its run function.
#pragma once

#include <CLI/CLI.hpp>

namespace avatarbooth {

// `avatarbooth fit`: a front + side photo pair to a textured head in an output folder.
void registerFitCommand(CLI::App& app);
// `avatarbooth batch`: many photo pairs (a folder of session folders or a CSV manifest) on N workers, with a report.
void registerBatchCommand(CLI::App& app);
// `avatarbooth make-base-head`: writes the built-in base head and its feature file, to study or edit.
void registerMakeBaseHeadCommand(CLI::App& app);
// `avatarbooth make-visitor`: writes a synthetic visitor's session folder (photos with known ground truth).
void registerMakeVisitorCommand(CLI::App& app);
// `avatarbooth run`: the kiosk (real devices when present, else the simulated booth).
void registerRunCommand(CLI::App& app);
// `avatarbooth check`: the hardware and set-up self-test (exit code non-zero when something needed is missing).
void registerCheckCommand(CLI::App& app);
// `avatarbooth retention`: applies the sessions' retention rules once (the timer's job when the booth is stopped).
void registerRetentionCommand(CLI::App& app);
// `avatarbooth config`: prints the documented default configuration or its Markdown reference, or checks a file.
void registerConfigCommand(CLI::App& app);
// `avatarbooth share`: serves the visitors' own pages (the QR code on the thanks screen), until stopped.
void registerShareCommand(CLI::App& app);
// `avatarbooth bench`: per-stage fit times on one photo pair.
void registerBenchCommand(CLI::App& app);
// `avatarbooth toon`: a front + side photo pair to Kitamura's two-view toon head, as a turntable strip of PNGs.
void registerToonCommand(CLI::App& app);

}  // namespace avatarbooth
