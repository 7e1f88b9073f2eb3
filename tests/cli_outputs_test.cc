// What every command writes (cli/command_outputs.h): never over a file it
// reads — whatever the spelling, through a symbolic or a hard link, an
// include or its own output folder — (exit 2, nothing written), and all of
// its outputs or none: a destination that cannot be written (the outputs,
// the depfile, the cache, a preview, a plot) fails the command with nothing
// written anywhere (exit 1). No GPU is needed: preview and sweep check their
// outputs before they render.
#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cli/cli.h"
#include "cli_util.h"
#include "output/atomic_write.h"
#include "output/file_identity.h"
#include "preview/image.h"

namespace fs = std::filesystem;
using substratec::clitest::cli;
using substratec::clitest::CliResult;
using substratec::clitest::slurp;

namespace cli_outputs_test {

const fs::path kSource = SUBSTRATEC_SOURCE_DIR;

fs::path freshDir(const std::string& name) {
  fs::path d = substratec::clitest::freshDir("outputs", name);
  fs::create_directories(d);
  return d;
}

/// Every entry under `dir` (files with their bytes, directories, links),
/// temporaries included, so that anything written shows up.
std::map<std::string, std::string> tree(const fs::path& dir) {
  std::map<std::string, std::string> out;
  if (!fs::exists(dir)) return out;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    const std::string name = e.path().lexically_relative(dir).string();
    if (e.is_symlink()) out[name] = "-> " + fs::read_symlink(e.path()).string();
    else if (e.is_directory()) out[name] = "<dir>";
    else out[name] = slurp(e.path());
  }
  return out;
}

/// examples/row12_simple.json copied into `dir` as `name`.
fs::path material(const fs::path& dir, const std::string& name = "row12_simple.json") {
  fs::copy_file(kSource / "examples/row12_simple.json", dir / name, fs::copy_options::overwrite_existing);
  return dir / name;
}

/// A MaterialX file whose shader is in an included file.
fs::path mtlxWithInclude(const fs::path& dir) {
  const char* head = "<?xml version=\"1.0\"?>\n<materialx version=\"1.39\" xmlns:xi=\"http://www.w3.org/2001/XInclude\">\n";
  std::ofstream(dir / "shader.mtlx") << head << "  <standard_surface name=\"SR\" type=\"surfaceshader\" />\n</materialx>\n";
  std::ofstream(dir / "gold.mtlx") << head << "  <xi:include href=\"shader.mtlx\" />\n"
                                   << "  <surfacematerial name=\"Gold\" type=\"material\">\n"
                                   << "    <input name=\"surfaceshader\" type=\"surfaceshader\" nodename=\"SR\" />\n"
                                   << "  </surfacematerial>\n</materialx>\n";
  return dir / "gold.mtlx";
}

/// A scene of one material, in `dir`.
fs::path sceneIn(const fs::path& dir) {
  material(dir);
  std::ofstream(dir / "scene.json") << R"({ "format": "substrate-scene/1", "name": "s", "materials": ["row12_simple.json"] })";
  return dir / "scene.json";
}

/// Runs the command, expecting the refusal of an output that is an input:
/// exit 2, the error, nothing on stdout, and `dir` exactly as it was.
void expectRefused(const std::vector<std::string>& args, const fs::path& dir, const std::string& message) {
  const auto before = tree(dir);
  CliResult r = cli(args);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find(message), std::string::npos) << r.err;
  EXPECT_EQ(r.out, "");
  EXPECT_EQ(tree(dir), before);
}

/// Runs the command, expecting a destination that cannot be written: exit
/// 1 naming it, and `dir` exactly as it was.
void expectUnwritable(const std::vector<std::string>& args, const fs::path& dir, const std::string& destination) {
  const auto before = tree(dir);
  CliResult r = cli(args);
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("cannot "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(destination), std::string::npos) << r.err;
  EXPECT_EQ(r.out, "");
  EXPECT_EQ(tree(dir), before);
}

// --- an output that is an input: exit 2, nothing written ---------------------

TEST(OutputsAreNotInputs, CompileRefusesADepfileThatIsItsInputHoweverSpelled) {
  const fs::path dir = freshDir("compile_depfile");
  const fs::path d = material(dir, "d.json");
  fs::create_directories(dir / "sub");
  fs::create_symlink("d.json", dir / "link.d");
  fs::create_hard_link(d, dir / "hard.d");
  for (const std::string& depfile : {(dir / "sub/../d.json").string(), (dir / "nosuchdir/../d.json").string(), (dir / "./d.json").string(),
                                     (dir / "link.d").string(), (dir / "hard.d").string()}) {
    SCOPED_TRACE(depfile);
    expectRefused({"compile", d.string(), "-o", (dir / "dd").string(), "--depfile", depfile}, dir,
                  "is the input '" + d.string() + "' (the same file); refusing to overwrite it");
  }
  // Spelled as the input itself.
  expectRefused({"compile", d.string(), "-o", (dir / "dd").string(), "--depfile", d.string()}, dir,
                "output '" + d.string());
}

// A material named m in m.layout.json, compiled into its own folder: one of
// its outputs is the input file itself.
TEST(OutputsAreNotInputs, CompileRefusesToWriteAMaterialOverItselfInItsOwnFolder) {
  const fs::path dir = freshDir("compile_own_folder");
  std::string text = slurp(kSource / "examples/row12_simple.json");
  text.replace(text.find("\"row12_simple\""), 14, "\"m\"");
  std::ofstream(dir / "m.layout.json") << text;
  expectRefused({"compile", (dir / "m.layout.json").string(), "-o", dir.string()}, dir,
                "output '" + (dir / "m.layout.json").string() + "' is an input");
  // The folder spelled another way, and an output hard-linked to an input.
  expectRefused({"compile", (dir / "m.layout.json").string(), "-o", (dir / "." / ".").string()}, dir,
                "(the same file); refusing to overwrite it");
  const fs::path other = freshDir("compile_hard_link");
  const fs::path in = material(other);
  fs::create_directories(other / "out");
  fs::create_hard_link(in, other / "out/row12_simple.material.glsl");
  expectRefused({"compile", in.string(), "-o", (other / "out").string()}, other, "(the same file)");
}

// Two outputs that are one file: the depfile over one of the shaders.
TEST(OutputsAreNotInputs, CompileRefusesTwoOutputsThatAreOneFile) {
  const fs::path dir = freshDir("compile_two_outputs");
  const fs::path in = material(dir);
  expectRefused({"compile", in.string(), "-o", (dir / "out").string(), "--depfile",
                 (dir / "out/row12_simple.layout.json").string()},
                dir, "are the same file; one would overwrite the other");
}

// What a command read through an include is an input as well.
TEST(OutputsAreNotInputs, AnIncludedFileIsAnInput) {
  const fs::path dir = freshDir("include");
  const fs::path gold = mtlxWithInclude(dir);
  expectRefused({"compile", gold.string(), "-o", (dir / "out").string(), "--depfile", (dir / "shader.mtlx").string()},
                dir, "output '" + (dir / "shader.mtlx").string() + "' is an input");
  ASSERT_EQ(cli({"compile", gold.string(), "-o", (dir / "out").string()}).status, 0);  // and without the clash, it compiles
}

// ... and so a prerequisite in the depfile: a build system rebuilds when an
// include changes. A cache entry used is not one.
TEST(OutputsAreNotInputs, AnIncludedFileIsADepfilePrerequisite) {
  const fs::path dir = freshDir("include_depfile");
  const fs::path gold = mtlxWithInclude(dir);
  for (int run = 0; run < 2; ++run) {  // the second from the cache
    CliResult r = cli({"compile", gold.string(), "-o", (dir / "out").string(), "--depfile", (dir / "out.d").string(),
                       "--cache", (dir / "cache").string()});
    ASSERT_EQ(r.status, 0) << r.err;
    const std::string depfile = slurp(dir / "out.d");
    EXPECT_NE(depfile.find(" \\\n  " + gold.string() + " \\\n  " + (dir / "shader.mtlx").string() + "\n"),
              std::string::npos)
        << depfile;
    EXPECT_EQ(depfile.find(".entry"), std::string::npos) << depfile;
  }
}

// A cache entry the command used is an input too (one it ignored, being
// corrupt, it rewrites as the cache's own).
TEST(OutputsAreNotInputs, ACacheEntryUsedIsAnInput) {
  const fs::path dir = freshDir("cache_entry");
  const fs::path in = material(dir);
  const std::vector<std::string> run = {"compile", in.string(), "-o", (dir / "out").string(), "--cache",
                                        (dir / "cache").string()};
  ASSERT_EQ(cli(run).status, 0);
  fs::path entry;
  for (const auto& e : fs::recursive_directory_iterator(dir / "cache"))
    if (e.path().extension() == ".entry") entry = e.path();
  ASSERT_FALSE(entry.empty());
  std::vector<std::string> withDepfile = run;
  withDepfile.insert(withDepfile.end(), {"--depfile", entry.string()});
  expectRefused(withDepfile, dir, "output '" + entry.string() + "' is an input");
}

TEST(OutputsAreNotInputs, PreviewRefusesToWriteOverItsInput) {
  const fs::path dir = freshDir("preview");
  const fs::path p = material(dir, "p.json");
  expectRefused({"preview", p.string(), "-o", p.string()}, dir, "output '" + p.string() + "' is an input");
  fs::create_symlink("p.json", dir / "p.png");
  expectRefused({"preview", p.string(), "-o", (dir / "p.png").string()}, dir, "(the same file)");
}

/// A texture's image is an input of the preview too (issue 20): an output
/// over it, by --texture or by the input's own file, is refused before any
/// rendering, and the image is left as it was.
TEST(OutputsAreNotInputs, PreviewRefusesToWriteOverATexturesImage) {
  const fs::path dir = freshDir("preview_texture");
  fs::create_directories(dir);
  substratec::Diagnostics d("albedo.png");
  ASSERT_TRUE(substratec::preview::writePng((dir / "albedo.png").string(), 1, 1, {10, 20, 30, 255}, d)) << d.formatAll();
  std::ofstream(dir / "t.json") << R"({"format": "substrate-material/1", "name": "t",
    "inputs": {"albedo": {"type": "texture2d", "file": "albedo.png"}},
    "nodes": {"a": {"kind": "texture", "texture": "$albedo"}, "root": {"kind": "slab", "diffuse_albedo": "a"}},
    "output": "root"})";
  const std::string image = (dir / "albedo.png").string();
  expectRefused({"preview", (dir / "t.json").string(), "-o", image}, dir, "output '" + image + "' is an input");
}

TEST(OutputsAreNotInputs, SweepRefusesAPlotOverItsInput) {
  const fs::path dir = freshDir("sweep");
  const fs::path s = material(dir, "s.json");
  expectRefused({"sweep", s.string(), "--plot", s.string()}, dir, "output '" + s.string() + "' is an input");
  const fs::path gold = mtlxWithInclude(dir);
  expectRefused({"sweep", gold.string(), "--plot", (dir / "shader.mtlx").string()}, dir,
                "output '" + (dir / "shader.mtlx").string() + "' is an input");
}

TEST(OutputsAreNotInputs, ReportHtmlRefusesAPageOverItsInputOrAnIncludedFile) {
  const fs::path dir = freshDir("report_html");
  const fs::path r = material(dir, "r.json");
  expectRefused({"report", r.string(), "--html", r.string()}, dir, "output '" + r.string() + "' is an input");
  const fs::path gold = mtlxWithInclude(dir);
  expectRefused({"report", gold.string(), "--html", (dir / "shader.mtlx").string()}, dir,
                "output '" + (dir / "shader.mtlx").string() + "' is an input");
}

TEST(OutputsAreNotInputs, ImportRefusesToWriteOverItsInput) {
  const fs::path dir = freshDir("import");
  const fs::path gold = mtlxWithInclude(dir);
  fs::create_directories(dir / "out");
  fs::create_hard_link(dir / "shader.mtlx", dir / "out/Gold.json");  // the included file, by another name
  expectRefused({"import", gold.string(), "-o", (dir / "out").string()}, dir, "(the same file)");
  fs::remove(dir / "out/Gold.json");
  fs::create_symlink("../gold.mtlx", dir / "out/Gold.json");
  expectRefused({"import", gold.string(), "-o", (dir / "out").string()}, dir, "(the same file)");
}

TEST(OutputsAreNotInputs, SceneRefusesADepfileOrAnOutputThatIsAnInput) {
  const fs::path dir = freshDir("scene");
  const fs::path manifest = sceneIn(dir);
  expectRefused({"scene", manifest.string(), "-o", (dir / "out").string(), "--depfile", manifest.string()}, dir,
                "output '" + manifest.string() + "' is an input");
  // A material of the scene, where the scene writes its shaders.
  expectRefused({"scene", manifest.string(), "-o", (dir / "out").string(), "--depfile",
                 (dir / "out/../row12_simple.json").string()},
                dir, "is the input");
}

// report and stability write only to standard output: redirected onto an
// input (>> appends to it), they refuse before reading it.
TEST(OutputsAreNotInputs, ReportAndStabilityRefuseAStandardOutputThatIsTheirInput) {
  const fs::path dir = freshDir("stdout");
  const fs::path m = material(dir, "m.json");
  const std::string before = slurp(m);
  for (const std::string command : {"report", "stability --no-gpu --evaluations 10"}) {
    SCOPED_TRACE(command);
    const std::string run = std::string(SUBSTRATEC_BINARY) + " " + command + " " + m.string() + " >> " + m.string() +
                            " 2> " + (dir / "err.txt").string();
    const int st = std::system(run.c_str());
    ASSERT_TRUE(WIFEXITED(st));
    EXPECT_EQ(WEXITSTATUS(st), 2);
    EXPECT_NE(slurp(dir / "err.txt").find("standard output is the input '" + m.string() + "' (the same file); refusing to write to it"), std::string::npos)
        << slurp(dir / "err.txt");
    EXPECT_EQ(slurp(m), before);
  }
  // Standard output to another file is fine.
  const std::string ok = std::string(SUBSTRATEC_BINARY) + " report " + m.string() + " > " + (dir / "r.txt").string();
  EXPECT_EQ(std::system(ok.c_str()), 0);
}

// preview -o DIR: a usage error naming the directory, nothing rendered.
TEST(OutputsAreNotInputs, PreviewIntoADirectoryIsAUsageErrorNamingIt) {
  const fs::path dir = freshDir("preview_dir");
  const fs::path p = material(dir);
  fs::create_directories(dir / "pictures");
  expectRefused({"preview", p.string(), "-o", (dir / "pictures").string()}, dir,
                "output '" + (dir / "pictures").string() + "' is a directory; expected the name of a file");
  expectRefused({"sweep", p.string(), "--plot", (dir / "pictures").string()}, dir, "is a directory");
  expectRefused({"compile", p.string(), "-o", (dir / "out").string(), "--depfile", (dir / "pictures").string()}, dir,
                "is a directory");
}

// The identity check itself: by device and inode, not by name.
TEST(OutputsAreNotInputs, SameFileAsInputComparesIdentityNotSpelling) {
  using substratec::sameFileAsInput;
  const fs::path dir = freshDir("identity");
  material(dir, "a.json");
  const std::vector<substratec::InputFile> inputs = {{(dir / "a.json").string(), *substratec::fileIdOf((dir / "a.json").string())}};
  EXPECT_NE(sameFileAsInput({(dir / "a.json").string()}, inputs), "");
  EXPECT_NE(sameFileAsInput({(dir / "x/../a.json").string()}, inputs), "") << "x does not exist; a.json does";
  EXPECT_EQ(sameFileAsInput({(dir / "b.json").string(), (dir / "new/dir/c.json").string()}, inputs), "");
  EXPECT_NE(sameFileAsInput({(dir / "new/c.json").string(), (dir / "new/./c.json").string()}, inputs), "")
      << "two spellings of one file that does not exist yet";
  EXPECT_EQ(sameFileAsInput({}, inputs), "");
}

// --- all or none: a destination that cannot be written, nothing written ------

// The issue's case: the depfile cannot be written, so neither are the shaders.
TEST(AllOrNone, CompileWithAnUnwritableDepfileWritesNothing) {
  const fs::path dir = freshDir("depfile");
  const fs::path in = material(dir);
  expectUnwritable({"compile", in.string(), "-o", (dir / "okdir").string(), "--depfile", "/proc/x.d"}, dir, "/proc/x.d");
  EXPECT_FALSE(fs::exists(dir / "okdir"));
  // Over an earlier build: every file as it was.
  ASSERT_EQ(cli({"compile", in.string(), "-o", (dir / "okdir").string()}).status, 0);
  expectUnwritable({"compile", "--budget", "8", "--full-simplification", in.string(), "-o", (dir / "okdir").string(),
                    "--depfile", (dir / "row12_simple.json/x.d").string()},
                   dir, "x.d");
}

TEST(AllOrNone, CompileWithAnUnwritableOutputFolderOrCacheWritesNothing) {
  const fs::path dir = freshDir("folder_cache");
  const fs::path in = material(dir);
  expectUnwritable({"compile", in.string(), "-o", "/proc/substratec-out"}, dir, "/proc/substratec-out");
  expectUnwritable({"compile", in.string(), "-o", (dir / "row12_simple.json/out").string()}, dir, "out");
  expectUnwritable({"compile", in.string(), "-o", (dir / "okdir").string(), "--depfile", (dir / "okdir.d").string(),
                    "--cache", "/proc/substratec-cache"},
                   dir, "/proc/substratec-cache");
  expectUnwritable({"compile", in.string(), "-o", (dir / "okdir").string(), "--cache",
                    (dir / "row12_simple.json/cache").string()},
                   dir, "cache");
  EXPECT_FALSE(fs::exists(dir / "okdir"));
  // A writable cache: its entry is written with the outputs.
  CliResult r = cli({"compile", in.string(), "-o", (dir / "okdir").string(), "--cache", (dir / "cache").string()});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");
  std::size_t entries = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir / "cache")) entries += e.path().extension() == ".entry";
  EXPECT_EQ(entries, 1u);
}

// A material that fails stores no cache entry for the ones that compiled
// either: the command wrote nothing.
TEST(AllOrNone, AFailedCompileWritesNoCacheEntry) {
  const fs::path dir = freshDir("failed_cache");
  const fs::path good = material(dir);
  std::string broken = slurp(good);
  broken.replace(broken.find("\"$roughness\""), 12, "\"$no_such_input\"");
  std::ofstream(dir / "broken.json") << broken;
  CliResult r = cli({"compile", good.string(), (dir / "broken.json").string(), "-o", (dir / "out").string(), "--cache",
                     (dir / "cache").string()});
  EXPECT_EQ(r.status, 1);
  EXPECT_FALSE(fs::exists(dir / "out"));
  EXPECT_FALSE(fs::exists(dir / "cache"));
}

TEST(AllOrNone, PreviewAndSweepWithAnUnwritableOutputFailBeforeTheirWork) {
  const fs::path dir = freshDir("preview_sweep");
  const fs::path in = material(dir);
  expectUnwritable({"preview", in.string(), "-o", "/proc/substratec.png"}, dir, "/proc/substratec.png");
  expectUnwritable({"preview", in.string(), "-o", (dir / "row12_simple.json/p.png").string()}, dir, "p.png");
  expectUnwritable({"sweep", in.string(), "--plot", "/proc/substratec.svg"}, dir, "/proc/substratec.svg");
}

TEST(AllOrNone, SceneWithAnUnwritableDestinationWritesNothing) {
  const fs::path dir = freshDir("scene_unwritable");
  const fs::path manifest = sceneIn(dir);
  expectUnwritable({"scene", manifest.string(), "-o", "/proc/substratec-scene"}, dir, "/proc/substratec-scene");
  expectUnwritable({"scene", manifest.string(), "-o", (dir / "out").string(), "--depfile", "/proc/scene.d"}, dir,
                   "/proc/scene.d");
  expectUnwritable({"scene", manifest.string(), "-o", (dir / "out").string(), "--cache", "/proc/scene-cache"}, dir,
                   "/proc/scene-cache");
  EXPECT_FALSE(fs::exists(dir / "out"));
}

TEST(AllOrNone, ImportIntoAnUnwritableFolderWritesNothing) {
  const fs::path dir = freshDir("import_unwritable");
  const fs::path gold = mtlxWithInclude(dir);
  expectUnwritable({"import", gold.string(), "-o", "/proc/substratec-import"}, dir, "/proc/substratec-import");
}

// The writer across folders: a destination that fails when its temporary is
// written (its folder is a file), or when it is renamed into place (a
// directory holds its name), leaves every folder as it was.
TEST(AllOrNone, WritePathsAtomicallyCommitsAcrossFoldersOrNothing) {
  using substratec::writePathsAtomically;
  const fs::path dir = freshDir("writer");
  fs::create_directories(dir / "a");
  std::ofstream(dir / "a/kept.txt") << "old";
  std::ofstream(dir / "file") << "a file, not a folder";
  const auto before = tree(dir);
  EXPECT_NE(writePathsAtomically({{(dir / "a/kept.txt").string(), "new"},
                                  {(dir / "b/c/new.txt").string(), "new"},
                                  {(dir / "file/x.d").string(), "x"}}),
            "");
  EXPECT_EQ(tree(dir), before);
  fs::create_directories(dir / "d/taken.txt/inside");
  const auto before2 = tree(dir);
  const std::string error = writePathsAtomically({{(dir / "a/kept.txt").string(), "new"},
                                                  {(dir / "b/new.txt").string(), "new"},
                                                  {(dir / "d/taken.txt").string(), "x"}});
  EXPECT_NE(error.find("cannot rename into"), std::string::npos) << error;
  EXPECT_EQ(tree(dir), before2);
  EXPECT_EQ(writePathsAtomically({{(dir / "a/kept.txt").string(), "new"}, {(dir / "b/new.txt").string(), "new"}}), "");
  EXPECT_EQ(slurp(dir / "a/kept.txt"), "new");
  EXPECT_EQ(slurp(dir / "b/new.txt"), "new");
}

// Probing a destination before the work creates nothing another process could
// see: a probe that made a missing folder and removed it again raced with a
// concurrent compile writing into that folder (two compiles of one CMake
// target, their depfiles in one new folder: one lost its folder between two
// mkdirs). The folder is made only by the all-or-none commit.
TEST(AllOrNone, AProbeOfADestinationInAMissingFolderCreatesNothing) {
  const fs::path dir = freshDir("probe_creates_nothing");
  const fs::path file = dir / "a/b/x.d";
  // A folder made and removed again leaves no entry, but it moves the
  // parent's modification time: wait past the clock's tick, then compare.
  auto mtime = [](const fs::path& p) {
    struct stat st {};
    ::stat(p.c_str(), &st);
    return std::pair(st.st_mtim.tv_sec, st.st_mtim.tv_nsec);
  };
  ::usleep(50 * 1000);
  const auto before = mtime(dir);
  EXPECT_EQ(substratec::checkWritable({file.string()}), "");
  EXPECT_FALSE(fs::exists(dir / "a")) << "the probe left the folder";
  EXPECT_EQ(mtime(dir), before) << "the probe created (and removed) an entry in " << dir;
  EXPECT_EQ(substratec::checkWritableDirectory((dir / "c/d").string()), "");
  EXPECT_FALSE(fs::exists(dir / "c"));
  // Where the folder exists, the probe's temporary is gone after it.
  fs::create_directories(dir / "e");
  EXPECT_EQ(substratec::checkWritable({(dir / "e/x.d").string()}), "");
  EXPECT_TRUE(fs::is_empty(dir / "e"));
  // A file where a folder is needed is still an error.
  std::ofstream(dir / "f") << "x";
  EXPECT_NE(substratec::checkWritable({(dir / "f/x.d").string()}).find("is not a directory"), std::string::npos);
}

}  // namespace cli_outputs_test
