// Tests of the conventions every `pvs` command shares, run as a user runs
// them: outputs checked before any work (exit 2 naming the path and the problem, parent folders
// created, no checkpoint left), -v/-q on every command, -j, --preset, the unknown option named
// first, validator messages without DBL_MAX, and progress inside a long cell.
#include <gtest/gtest.h>

#include <cctype>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>

#include "pvs_format/pvs_format.h"
#include "tests/test_support.h"
#include "vislib/bake/bake.h"
#include "vislib/bake/checkpoint.h"
#include "vislib/base/file_util.h"

using namespace vislib_test;
using json = nlohmann::json;
namespace fs = std::filesystem;

namespace {

// A 2 x 2 block city, generated once per test binary run.
const std::string& city() {
  static const std::string path = [] {
    std::string p = temp_dir("cli_options_city") + "/city.glb";
    std::string out;
    EXPECT_EQ(run_pvs("generate city --blocks 2,2 -q -o " + p, &out), 0) << out;
    return p;
  }();
  return path;
}

// 4 grid cells at a tiny resolution.
std::string small_bake(const std::string& extra) {
  return "bake " + city() + " --box -30,0,-30,30,3,30 --grid 2,1,2 --eye-height 1.5,1.8 --res 16 " +
         extra;
}

std::vector<std::string> subcommands() {
  std::string out;
  EXPECT_EQ(run_pvs("--help", &out), 0);
  std::vector<std::string> cmds;
  std::istringstream in(out);
  std::string line;
  bool on = false;
  while (std::getline(in, line)) {
    if (line.rfind("Subcommands:", 0) == 0) {
      on = true;
      continue;
    }
    if (on && line.size() > 2 && line[0] == ' ' && line[1] == ' ' &&
        std::isalpha(static_cast<unsigned char>(line[2])))
      cmds.push_back(line.substr(2, line.find(' ', 2) - 2));
  }
  return cmds;
}

}  // namespace

// --- Item 1: output paths checked before any work ---------------------------------------------

TEST(CliOutputs, BakeIntoAFolderFailsBeforeBakingAndLeavesNoCheckpoint) {
  std::string dir = temp_dir("cli_out_bake") + "/adir";
  fs::create_directories(dir);
  std::string out;
  EXPECT_EQ(run_pvs(small_bake("-o " + dir), &out), 2) << out;
  EXPECT_NE(out.find(dir), std::string::npos) << out;
  EXPECT_NE(out.find("is a folder"), std::string::npos) << out;
  EXPECT_EQ(out.find("cells"), std::string::npos) << "no progress: nothing was baked\n" << out;
  EXPECT_FALSE(fs::exists(dir + ".ckpt"));
  // The bake report path too.
  EXPECT_EQ(run_pvs(small_bake("--json " + dir + " -o " + dir + "/x.pvs"), &out), 2) << out;
  EXPECT_NE(out.find("--json"), std::string::npos) << out;
  EXPECT_FALSE(fs::exists(dir + "/x.pvs.ckpt"));
}

TEST(CliOutputs, SegmentExportAndBenchNameTheBadPath) {
  std::string base = temp_dir("cli_out_misc");
  std::string dir = base + "/adir", file = base + "/afile";
  fs::create_directories(dir);
  std::ofstream(file) << "x";
  std::string out;
  EXPECT_EQ(
      run_pvs("segment " + city() + " --from 0,1.6,0 --to 1,1.6,0 --res 8 --json " + dir, &out), 2)
      << out;
  EXPECT_NE(out.find(dir + "' is a folder"), std::string::npos) << out;
  EXPECT_EQ(run_pvs("export " + city() + " -o " + dir, &out), 2) << out;
  EXPECT_NE(out.find(dir + "' is a folder"), std::string::npos) << out;
  EXPECT_EQ(run_pvs("bench " + city() + " --box -1,1.6,-1,1,1.6,1 --res 8 --out " + file, &out), 2)
      << out;
  EXPECT_NE(out.find(file + "' exists and is not a folder"), std::string::npos) << out;
  EXPECT_EQ(out.find("filesystem error"), std::string::npos) << out;
  // A parent that is a file.
  EXPECT_EQ(run_pvs("export " + city() + " -o " + file + "/x.obj", &out), 2) << out;
  EXPECT_NE(out.find("is not a folder"), std::string::npos) << out;
}

TEST(CliOutputs, ParentFoldersAreCreatedForEveryOutput) {
  std::string base = temp_dir("cli_out_parents");
  std::string out;
  EXPECT_EQ(run_pvs("export " + city() + " -o " + base + "/e/f/flat.obj", &out), 0) << out;
  EXPECT_TRUE(fs::exists(base + "/e/f/flat.obj"));
  EXPECT_EQ(run_pvs("segment " + city() + " --from 0,1.6,0 --to 1,1.6,0 --res 8 --json " + base +
                        "/s/t/seg.json",
                    &out),
            0)
      << out;
  EXPECT_TRUE(fs::exists(base + "/s/t/seg.json"));
  EXPECT_EQ(run_pvs(small_bake("-q --json " + base + "/r/report.json -o " + base + "/b/c/city.pvs"),
                    &out),
            0)
      << out;
  EXPECT_TRUE(fs::exists(base + "/b/c/city.pvs"));
  EXPECT_TRUE(fs::exists(base + "/r/report.json"));
  // pvs view -o into a missing folder (it failed before).
  EXPECT_EQ(run_pvs("view " + base + "/b/c/city.pvs --scene " + city() +
                        " --at -15,1.6,-15 --look 10,1.6,0 --centre -15,1.65,-15 --near-far 5,10 "
                        "--frame 32x24 -o " +
                        base + "/v/w/frame.png",
                    &out),
            0)
      << out;
  EXPECT_TRUE(fs::exists(base + "/v/w/frame.png"));
}

// --- Item 2: option conventions ---------------------------------------------------------------

TEST(CliConventions, EveryCommandTakesVerboseAndQuiet) {
  auto cmds = subcommands();
  ASSERT_GE(cmds.size(), 9u);
  for (const auto& c : cmds) {
    std::string out;
    EXPECT_EQ(run_pvs(c + " --help", &out), 0) << c;
    EXPECT_NE(out.find("-v,--verbose"), std::string::npos) << c;
    EXPECT_NE(out.find("-q,--quiet"), std::string::npos) << c;
  }
}

TEST(CliConventions, QuietSilencesProgressAndWarnings) {
  std::string dir = temp_dir("cli_quiet");
  std::string out;
  EXPECT_EQ(run_pvs(small_bake("-o " + dir + "/a.pvs"), &out), 0) << out;
  EXPECT_NE(out.find("cells"), std::string::npos) << "progress is shown by default\n" << out;
  EXPECT_EQ(run_pvs(small_bake("-q -o " + dir + "/b.pvs"), &out), 0) << out;
  EXPECT_EQ(out, "");
  // A warning (a face with 2 vertices is skipped) shows by default and not with -q.
  std::string obj = dir + "/warn.obj";
  std::ofstream(obj) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2\n";
  EXPECT_EQ(run_pvs("info " + obj, &out), 0) << out;
  EXPECT_NE(out.find("warning"), std::string::npos) << out;
  EXPECT_EQ(run_pvs("info -q " + obj, &out), 0) << out;
  EXPECT_EQ(out.find("warning"), std::string::npos) << out;
  // -v says more than the default.
  std::string normal, verbose;
  EXPECT_EQ(run_pvs("export " + obj + " -o " + dir + "/n/flat.obj", &normal), 0) << normal;
  EXPECT_EQ(run_pvs("export -v " + obj + " -o " + dir + "/m/flat.obj", &verbose), 0) << verbose;
  EXPECT_GT(verbose.size(), normal.size()) << verbose;
}

// The -q audit: every command run with -q on inputs that make it warn and report
// progress leaves stderr empty, and commands whose results go to files leave stdout empty too;
// each input is first run without -q to show that it does warn (so the check can fail). Errors
// still print with -q.
TEST(CliConventions, QuietLeavesStderrEmptyOnCommandsThatWarn) {
  const std::string dir = temp_dir("cli_quiet_all");
  std::string out, err;
  // The city as OBJ plus a face of 2 vertices: every command that loads it warns (skipped face).
  const std::string obj = dir + "/city.obj";
  ASSERT_EQ(run_pvs("export -q " + city() + " -o " + obj, &out), 0) << out;
  std::ofstream(obj, std::ios::app) << "f 1 2\n";
  // With -q stdout is expected empty too (results in files) unless `results_on_stdout`.
  auto check = [&](const std::string& what, const std::string& args, bool results_on_stdout,
                   const std::string& warning) {
    ASSERT_EQ(run_pvs_split(args, &out, &err), 0) << what << "\n" << out << err;
    EXPECT_NE(err.find(warning), std::string::npos)
        << what << ": warns without -q (" << warning << ")\n"
        << err;
    ASSERT_EQ(run_pvs_split(args + " -q", &out, &err), 0) << what << "\n" << out << err;
    EXPECT_EQ(err, "") << what << " -q";
    if (!results_on_stdout) {
      EXPECT_EQ(out, "") << what << " -q";
    }
  };
  const std::string warned = "warning";
  check("info", "info " + obj, true, warned);
  check("export", "export " + obj + " -o " + dir + "/e.obj", false, warned);
  check("generate", "generate city --blocks 1,1 -o " + dir + "/g.glb", false, "");
  check("segment",
        "segment " + obj + " --from 0,1.6,0 --to 1,1.6,0 --res 8 --json " + dir + "/s.json", false,
        warned);
  check("region", "region " + obj + " --box -1,1.6,-1,1,1.6,1 --res 8 --json " + dir + "/r.json",
        false, warned);
  const std::string bake =
      "bake " + obj + " --box -30,0,-30,30,3,30 --grid 2,1,2 --eye-height 1.5,1.8 --res 16 ";
  check("bake", bake + "-o " + dir + "/a.pvs", false, warned);
  for (const char* shard : {"0/2", "1/2"})
    ASSERT_EQ(run_pvs(bake + "-q --shard " + shard + " -o " + dir + "/s" + shard[0] + ".pvs", &out),
              0)
        << out;
  check("merge", "merge " + dir + "/s0.pvs " + dir + "/s1.pvs -o " + dir + "/m.pvs", false,
        "pvs merge");
  // A resumed bake whose checkpoint has a damaged record warns that it was dropped.
  pvs::Reader baked = pvs::Reader::from_file(dir + "/a.pvs");
  auto damaged_checkpoint = [&] {
    const std::string ckpt = dir + "/r.pvs.ckpt";
    {
      vislib::Checkpoint cp(ckpt, vislib::bake_key(baked.info(), vislib::Shard{}),
                            baked.cell_count(), false);
      cp.append(0, baked.read_cell(0));
      cp.append(1, baked.read_cell(1));
    }
    std::string bytes = vislib::read_file(ckpt);
    bytes[bytes.size() - 6] ^= 0x10;  // inside the last record
    vislib::write_file_atomic(ckpt, bytes);
  };
  damaged_checkpoint();
  ASSERT_EQ(run_pvs_split(bake + "--resume -o " + dir + "/r.pvs", &out, &err), 0) << out << err;
  EXPECT_NE(err.find("damaged or torn record(s) dropped"), std::string::npos) << err;
  EXPECT_EQ(vislib::read_file(dir + "/r.pvs"), vislib::read_file(dir + "/a.pvs"));
  damaged_checkpoint();
  ASSERT_EQ(run_pvs_split(bake + "--resume -q -o " + dir + "/r.pvs", &out, &err), 0) << out << err;
  EXPECT_EQ(err, "") << "bake --resume -q";
  EXPECT_EQ(out, "") << "bake --resume -q";
  // inspect, view (near-far, ODS, stereo) and bench on the baked file.
  const std::string pvs = dir + "/a.pvs --scene " + obj;
  check("inspect", "inspect " + pvs + " --at -15,1.6,-15 --frame 32x24 --render " + dir + "/i",
        true, warned);
  const std::string view = "view " + pvs + " --at -15,1.6,-15 ";
  check("view", view + "--look 10,1.6,0 --frame 32x24 -o " + dir + "/v/f.png", false, warned);
  check("view --ods", view + "--ods --ods-size 32 -o " + dir + "/o/p.png", false, warned);
  check("view --stereo",
        view + "--look 10,1.6,0 --frame 32x24 --stereo yoro -o " + dir + "/t/f.png", false,
        "stereo");
  // Bench with plots (when /usr/bin/python3 has matplotlib: its script is silenced too) and a
  // from-point budget too small, which warns that from-point stopped.
  check("bench",
        "bench " + obj +
            " --box -1,1.6,-1,1,1.6,1 --res 16 --views 2 --frame 24x16 --max-point-runs 3 --out " +
            dir + "/b",
        false, warned);
  // Errors still print with -q.
  EXPECT_EQ(run_pvs_split("info -q " + dir + "/missing.obj", &out, &err), 2);
  EXPECT_NE(err.find("missing.obj"), std::string::npos) << err;
}

TEST(CliConventions, DashJIsThreads) {
  std::string dir = temp_dir("cli_j");
  std::string out;
  EXPECT_EQ(run_pvs(small_bake("-q -j 1 -o " + dir + "/a.pvs"), &out), 0) << out;
  EXPECT_EQ(run_pvs(small_bake("-q --threads 2 -o " + dir + "/b.pvs"), &out), 0) << out;
  EXPECT_EQ(vislib::read_file(dir + "/a.pvs"), vislib::read_file(dir + "/b.pvs"));
  for (const char* c : {"bake", "bench", "segment", "region"}) {
    EXPECT_EQ(run_pvs(std::string(c) + " --help", &out), 0);
    EXPECT_NE(out.find("-j,--threads"), std::string::npos) << c;
  }
  // -j N runs N threads, more than the cores too (cli/threads.h), with the same result.
  std::string visible[2];
  for (int i = 0; i < 2; ++i) {
    const std::string path = dir + "/s" + std::to_string(i) + ".json";
    ASSERT_EQ(run_pvs("segment " + city() + " --from 0,1.6,0 --to 1,1.6,0 --res 8 -j " +
                          (i ? "16" : "1") + " --json " + path,
                      &out),
              0)
        << out;
    visible[i] = json::parse(vislib::read_file(path))["visible"].dump();
  }
  EXPECT_EQ(visible[0], visible[1]);
  // Beyond kMaxThreads: refused, naming the option.
  EXPECT_EQ(run_pvs(small_bake("-j 5000 -o " + dir + "/c.pvs"), &out), 2) << out;
  EXPECT_NE(out.find("--threads"), std::string::npos) << out;
}

TEST(CliConventions, PresetSetsResolutionRunsAndCellSizeAndIsReported) {
  std::string dir = temp_dir("cli_preset");
  std::string out;
  std::string bake = "bake " + city() + " --walkable --box -12,-1,-12,12,1,12 ";
  ASSERT_EQ(
      run_pvs(bake + "--preset draft -q --json " + dir + "/d.json -o " + dir + "/d.pvs", &out), 0)
      << out;
  json d = json::parse(vislib::read_file(dir + "/d.json"));
  EXPECT_EQ(d["preset"]["name"], "draft");
  EXPECT_EQ(d["preset"]["res"], 128);
  EXPECT_EQ(d["preset"]["runs"], 1);
  EXPECT_EQ(d["preset"]["cell_size"], 8.0);
  // An explicit option wins over the preset, and the report says so.
  ASSERT_EQ(run_pvs(bake + "--preset draft --res 64 --json " + dir + "/e.json -o " + dir + "/e.pvs",
                    &out),
            0)
      << out;
  json e = json::parse(vislib::read_file(dir + "/e.json"));
  EXPECT_EQ(e["preset"]["res"], 64);
  EXPECT_NE(out.find("preset draft"), std::string::npos) << out;
  EXPECT_EQ(run_pvs(bake + "--preset fast -o " + dir + "/f.pvs", &out), 2) << out;
}

TEST(CliConventions, UnknownOptionIsNamedBeforeMissingRequiredOnes) {
  std::string out;
  EXPECT_EQ(run_pvs("bake " + city() + " --bogus", &out), 2) << out;
  EXPECT_NE(out.find("--bogus"), std::string::npos) << out;
  EXPECT_EQ(out.find("--output is required"), std::string::npos) << out;
  EXPECT_EQ(run_pvs("bake " + city() + " -x", &out), 2) << out;
  EXPECT_NE(out.find("-x"), std::string::npos) << out;
  EXPECT_EQ(out.find("is required"), std::string::npos) << out;
  // Without unknown options the missing one is still reported.
  EXPECT_EQ(run_pvs("bake " + city() + " -v", &out), 2) << out;
  EXPECT_NE(out.find("--output is required"), std::string::npos) << out;
}

TEST(CliConventions, ValidatorMessagesNeverPrintDblMax) {
  const std::vector<std::string> bad = {
      "bake " + city() + " --walkable --cell-size -1 -o x.pvs",
      "bake " + city() + " --walkable --near -1 -o x.pvs",
      "bake " + city() + " --walkable --res 0 -o x.pvs",
      "bake " + city() + " --walkable --states 0 -o x.pvs",
      "bake " + city() + " --walkable -j -1 -o x.pvs",
      "segment " + city() + " --from 0,0,0 --to 1,0,0 --near 0 --json -",
  };
  for (const auto& args : bad) {
    std::string out;
    EXPECT_EQ(run_pvs(args, &out), 2) << args << "\n" << out;
    EXPECT_EQ(out.find("179769"), std::string::npos) << args << "\n" << out;
    EXPECT_EQ(out.find("e+308"), std::string::npos) << args << "\n" << out;
    EXPECT_EQ(out.find("0.000000"), std::string::npos) << args << "\n" << out;
    EXPECT_NE(out.find("must be"), std::string::npos) << args << "\n" << out;
  }
}

TEST(CliConventions, ProgressShowsInsideALongCell) {
  // One cell, 2 orientations per segment: 16 runs. The progress lines (not a terminal: plain
  // lines) report the fraction of the running cell before the cell is done.
  std::string dir = temp_dir("cli_progress");
  std::string out;
  ASSERT_EQ(
      run_pvs("bake " + city() +
                  " --box -5,0,-5,5,3,5 --grid 1,1,1 --eye-height 1.5,1.8 --res 64 --runs 2 -o " +
                  dir + "/one.pvs",
              &out),
      0)
      << out;
  std::smatch m;
  EXPECT_TRUE(std::regex_search(out, m, std::regex("0/1 cells \\+ 0\\.[0-9]+ of running cells")))
      << out;
}
