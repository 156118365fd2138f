// Bad options and configurations: kfd-inject's outputs and models, duplicate keys, empty
// pipelines, hanging YAML.
#include "app_runner.h"
#include "bad_logs.h"

namespace {

using namespace kfd::test::apps;

TEST(BadOptions, OutputOnTheInputOrAnUnknownModelIsRefused) {
    Dir d;
    const auto in = d.copy(kOffice, "in.rawlog");
    const Snapshot snap({in});
    Result r = run(KFD_INJECT_EXE, {"-q", "-i", in, "-o", in}, d.path);
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.first(), "kfd-inject: the output rawlog " + in + " is the input rawlog " + in +
                             ": refusing to overwrite an input");
    r = run(KFD_INJECT_EXE, {"-q", "-i", in, "-o", d / "n.rawlog", "--model", "spike"}, d.path);
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.first().find("--model"), std::string::npos) << r.err;
    EXPECT_NE(r.first().find("unknown model 'spike'"), std::string::npos) << r.err;
    EXPECT_EQ(listing(d.path), std::set<std::string>{"in.rawlog"});
    // kfd-denoise-eval on labels with a model it does not know: the file and line named.
    const auto labels = d.write("l.csv", "scan,timestamp,beam,kind,model\n0,1.0,3,isolated,nope\n");
    const auto cfg = d.copy(kIni, "kfd.ini");
    r = run(KFD_DENOISE_EVAL_EXE, {"-i", in, "-l", labels, "-c", cfg}, d.path);
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.first(),
              "kfd-denoise-eval: " + labels + ":2: unknown noise model 'nope' in labels");
    snap.expectUnchanged();
}

// --- configuration ---

// kfd-filter with a bad configuration: exit 1, the first line, nothing written, inputs kept.
void expectConfigRefused(const std::string& name, const std::string& text,
                         const std::string& message) {
    SCOPED_TRACE(name);
    Dir d;
    const auto in = d.copy(kOffice, "in.rawlog");
    const auto cfg = d.write(name, text);
    const Snapshot snap({in, cfg});
    const Result r =
        run(KFD_FILTER_EXE,
            {"-q", "-i", in, "-c", cfg, "-o", d / "out.rawlog", "--stats", d / "s.csv"}, d.path);
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.first().rfind("kfd-filter: ", 0), 0u) << r.err;
    EXPECT_NE(r.first().find(message), std::string::npos) << r.err;
    EXPECT_EQ(listing(d.path), (std::set<std::string>{"in.rawlog", name}));
    snap.expectUnchanged();
}

TEST(BadOptions, DuplicateKeysEmptyPipelinesAndHangingYamlAreErrors) {
    expectConfigRefused("dup.ini", "[KFD]\nwindow = 3\nwindow = 4\n", "window");
    expectConfigRefused("dup.yaml", "window: 3\nwindow: 4\n", "window");
    expectConfigRefused("empty.ini", "[KFD]\npipeline =\n", "pipeline");
    expectConfigRefused("range.ini", "[KFD]\nwindow = 0\n", "window");
    // The 4 bytes that made MRPT's YAML parser (libfyaml) loop forever: refused at once.
    expectConfigRefused("hang.yaml",
                        fileBytes(std::string(KFD_SOURCE_DIR) + "/test/data/yaml-hang-4byte.yaml"),
                        "hang.yaml");
}

}  // namespace
