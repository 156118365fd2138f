// The ground-truth flags of kfd-eval and kfd-icp-slam, one meaning each in both tools:
//   -g, --ground-truth FILE  a ground truth in either format, told by content (up to one of each)
//   -r, --relations FILE     a relations file (t1 t2 x y z roll pitch yaw) only
//   --gt FILE                a TUM trajectory (t x y z qx qy qz qw) only
// A file whose content is the other format than its option says is a usage error naming what
// the file is and the option that takes it. Header-only: both apps link kfd::eval.
#pragma once

#include <string>
#include <vector>

#include "common/cli.h"
#include "kfd/eval/ground_truth.h"
#include "kfd/eval/trajectory.h"  // EvalError

namespace kfd::app {

struct GroundTruthArgs {
    std::vector<std::string> any;  // -g, --ground-truth (given up to twice)
    std::string relations;         // -r, --relations
    std::string tum;               // --gt
};

inline void addGroundTruthOptions(Cli& cli, GroundTruthArgs& a, const std::string& relations_help,
                                  const std::string& tum_help) {
    cli.app()
        .add_option("-g,--ground-truth", a.any,
                    "ground truth, a relations file or a TUM trajectory told\n"
                    "by content (give -g twice for both)")
        ->type_name("FILE")
        ->allow_extra_args(false);
    cli.option("-r,--relations", a.relations, relations_help)->type_name("FILE");
    cli.option("--gt", a.tum, tum_help)->type_name("FILE");
}

/// The relations file and the TUM ground truth the options name (empty when not given).
/// UsageError when a file under -r or --gt clearly is the other format, when a -g file is
/// neither clearly, or when two files of one kind are given.
inline void resolveGroundTruth(const GroundTruthArgs& a, std::string& relations, std::string& tum) {
    const auto wrong = [](const std::string& option, const std::string& path,
                          const kfd::GroundTruthGuess& g, const char* takes) {
        return UsageError(option + ": " + path + " is " + kfd::toString(g.format) + ", not " +
                          takes + " (" + g.evidence() + ")");
    };
    const auto set = [](std::string& slot, const std::string& path, const char* what) {
        if (!slot.empty())
            throw UsageError("two " + std::string(what) + ": " + slot + " and " + path);
        slot = path;
    };
    // -r and --gt: a file that cannot be read is left to the reader's error.
    const auto guess = [](const std::string& path) {
        try {
            return kfd::detectGroundTruthFormat(path);
        } catch (const kfd::EvalError&) {
            return kfd::GroundTruthGuess{};
        }
    };
    relations.clear();
    tum.clear();
    if (!a.relations.empty()) {
        const auto g = guess(a.relations);
        if (g.format == kfd::GroundTruthFormat::Tum)
            throw wrong("--relations", a.relations, g, "a relations file: give it with --gt or -g");
        relations = a.relations;
    }
    if (!a.tum.empty()) {
        const auto g = guess(a.tum);
        if (g.format == kfd::GroundTruthFormat::Relations)
            throw wrong("--gt", a.tum, g, "a TUM trajectory: give it with --relations or -g");
        tum = a.tum;
    }
    for (const auto& path : a.any) {
        const auto g = kfd::detectGroundTruthFormat(path);
        if (g.format == kfd::GroundTruthFormat::Relations)
            set(relations, path, "relations files");
        else if (g.format == kfd::GroundTruthFormat::Tum)
            set(tum, path, "ground-truth trajectories");
        else
            throw UsageError("--ground-truth: " + path + " is " + kfd::toString(g.format) + " (" +
                             g.evidence() + "): give it with --relations or --gt");
    }
}

}  // namespace kfd::app
