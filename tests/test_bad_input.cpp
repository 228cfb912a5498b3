// The bad-input catalogue (issue 18): every case runs the built `ranging` in a fresh folder
// and asserts exit status 2, stderr naming the file and line (where there is one), the key or
// option and the valid range (the case lists the substrings), nothing on stdout, and no file
// created or left behind in the folder or at the output path (the folder's tree is compared
// before and after). CRLF line endings and a UTF-8 BOM are accepted (the same output as the
// plain file). Captures are made with the model's own writers and then damaged.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <functional>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "model/base/atomic_file.hpp"
#include "model/base/error.hpp"
#include "model/sim/capture.hpp"
#include "tests/process.hpp"
#include "tests/scratch.hpp"

namespace fs = std::filesystem;
using ranging::testing_support::run_command;

namespace {

const std::string kSrc = RANGING_SOURCE_DIR;

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::string replace_all(std::string s, const std::string& from, const std::string& to) {
  for (std::size_t at = s.find(from); at != std::string::npos; at = s.find(from, at + to.size())) {
    s.replace(at, from.size(), to);
  }
  return s;
}

// Replaces the first line starting with `prefix` (after indentation) by `line`.
std::string set_line(const std::string& text, const std::string& prefix, const std::string& line) {
  std::istringstream in(text);
  std::ostringstream out;
  std::string l;
  bool done = false;
  while (std::getline(in, l)) {
    const auto b = l.find_first_not_of(' ');
    if (!done && b != std::string::npos && l.compare(b, prefix.size(), prefix) == 0) {
      out << line << "\n";
      done = true;
    } else {
      out << l << "\n";
    }
  }
  EXPECT_TRUE(done) << "no line starts with " << prefix;
  return out.str();
}

const std::string& default_config() {
  static const std::string t = slurp(kSrc + "/configs/default.yaml");
  return t;
}
const std::string kScene = "name: s\ngeometry:\n  distances_m: [0.5]\n";

std::string csv_capture(std::size_t n) {
  ranging::Capture c;
  c.sample_rate = 5e6;
  c.samples.assign(n, 0.01);
  return ranging::capture_csv(c);
}
std::string wav_capture(std::size_t n, double rate = 5e6) {
  ranging::Capture c;
  c.sample_rate = rate;
  c.samples.assign(n, 0.01);
  return ranging::capture_wav(c, ranging::WavFormat::Pcm16);
}
void put_le32(std::string& b, std::size_t at, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) b[at + static_cast<std::size_t>(i)] = static_cast<char>((v >> (8 * i)) & 0xFF);
}

const char* kDir = "<DIR>";  // file content that makes a folder instead

struct Case {
  std::string name;
  std::vector<std::pair<std::string, std::string>> files;  // name in the folder -> content
  std::string args;                                         // {d}: the folder
  std::vector<std::string> err;                             // stderr must contain each ({d} replaced)
  std::string redirect_stdout;                              // e.g. "/dev/full" (stdout then not captured)
  Case(std::string n, std::vector<std::pair<std::string, std::string>> f, std::string a, std::vector<std::string> e,
       std::string redirect = "")
      : name(std::move(n)), files(std::move(f)), args(std::move(a)), err(std::move(e)),
        redirect_stdout(std::move(redirect)) {}
};

void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }

std::vector<Case> catalogue() {
  const std::string& cfg = default_config();
  const std::string gen = "generate --out {d}/gen --config {d}/c.yaml";
  const std::string sim = "simulate {d}/s.yaml --quiet --out {d}/out";
  const std::string dec = "decode --family Gold4 ";
  std::string record_short = csv_capture(50);
  record_short = replace_all(record_short, "Record Length,50", "Record Length,80");
  std::string wav_long = wav_capture(50);
  put_le32(wav_long, 40, 4000);  // the data chunk claims 4000 bytes, the file holds 100
  std::string wav_fmt_long = wav_capture(50);
  put_le32(wav_fmt_long, 16, 100000);
  std::string deep = "name: ";
  for (int i = 0; i < 100; ++i) deep += "[";
  for (int i = 0; i < 100; ++i) deep += "]";
  deep += "\n";
  const std::string bomb =
      "a: &a [x,x,x,x,x,x,x,x,x,x]\nb: &b [*a,*a,*a,*a,*a,*a,*a,*a,*a,*a]\nc: &c [*b,*b,*b,*b,*b,*b,*b,*b,*b,*b]\n"
      "d: &d [*c,*c,*c,*c,*c,*c,*c,*c,*c,*c]\ne: &e [*d,*d,*d,*d,*d,*d,*d,*d,*d,*d]\n"
      "f: &f [*e,*e,*e,*e,*e,*e,*e,*e,*e,*e]\ng: &g [*f,*f,*f,*f,*f,*f,*f,*f,*f,*f]\n";

  return {
      // --- command line ---
      {"unknown command", {}, "bogus", {"unknown command 'bogus'", "commands:", "simulate"}},
      {"unknown option", {}, "demo --bogus", {"'--bogus'", "valid: --help, --config"}},
      {"option without its value", {}, "demo --family", {"--family", "needs a value"}},
      {"unknown family", {}, "demo --family Nope", {"'Nope'", "valid: M1"}},
      {"distance not a number", {}, "demo --distances 0.5,abc", {"--distances", "'abc'"}},
      {"distance out of range", {}, "demo --distances 25", {"--distances", "[0.01, 20]"}},
      {"NaN option", {}, "demo --noise-rms nan", {"--noise-rms", "valid range is"}},
      {"huge option", {}, "demo --speed-of-sound 1e400", {"--speed-of-sound", "valid range is [100, 10000]"}},
      {"filter type", {}, "filter --type bogus", {"--type", "butter"}},
      {"precision", {{"s.yaml", kScene}}, sim + " --precision double", {"--precision", "valid: float, fixed"}},
      {"missing positional", {}, "simulate", {"missing argument SCENE"}},
      {"simulate --timing of a rotor scene",
       {{"r.yaml", "name: r\ngeometry: {type: rotor, radius_m: 4.244, rpm: 60, h_m: [0.3], crossings: 1}\n"
                   "excitation: {family: M1, schedule: {mode: periodic, period_s: 0.00042}}\n"}},
       "simulate {d}/r.yaml --quiet --out {d}/out --timing", {"--timing", "not available for rotor scenes"}},
      {"demo --jobs 0", {}, "demo --jobs 0", {"--jobs", "[1, 256]"}},
      {"bitstream --min-seeds above --seeds", {{"c.yaml", cfg}},
       "bitstream --config {d}/c.yaml --out {d}/bit --seeds 2 --check --min-seeds 3",
       {"--min-seeds", "more than the 2 seed(s) tried", "valid: 1..2"}},
      {"decode without family", {{"x.csv", csv_capture(50)}}, "decode {d}/x.csv", {"--family", "required"}},
      {"decode min-rho out of range", {{"x.csv", csv_capture(50)}}, dec + "{d}/x.csv --min-rho 2",
       {"--min-rho", "[0, 1]"}},
      {"generate without --out", {{"c.yaml", cfg}}, "generate --config {d}/c.yaml", {"--out", "required"}},
      // --- receiver configuration ---
      {"config: duplicate key", {{"c.yaml", cfg + "name: again\n"}}, gen,
       {"c.yaml:" + std::to_string(std::count(cfg.begin(), cfg.end(), '\n') + 1) + ": name: duplicate key",
        "first at {d}/c.yaml:3"}},
      {"config: duplicate nested key", {{"c.yaml", set_line(cfg, "order:", "  order: 0\n  order: 5")}}, gen,
       {"c.yaml:13: filter.order: duplicate key", "first at {d}/c.yaml:12"}},
      {"config: non-UTF-8 byte", {{"c.yaml", set_line(cfg, "name:", "name: caf\xe9")}}, gen,
       {"c.yaml:3:", "0xE9", "valid: UTF-8"}},
      {"config: control character", {{"c.yaml", set_line(cfg, "name:", std::string("name: a\x01z"))}}, gen,
       {"c.yaml:3:", "control character 0x01"}},
      {"config: NaN as a string", {{"c.yaml", set_line(cfg, "fs:", "  fs: \"nan\"")}}, gen,
       {"c.yaml:9: signal.fs", "'nan' is not a finite number"}},
      {"config: .inf", {{"c.yaml", set_line(cfg, "fs:", "  fs: .inf")}}, gen, {"c.yaml:9: signal.fs", "finite"}},
      {"config: number beyond double", {{"c.yaml", set_line(cfg, "fs:", "  fs: 1e400")}}, gen,
       {"c.yaml:9: signal.fs", "'1e400' is not a finite number"}},
      {"config: huge number", {{"c.yaml", set_line(cfg, "fs:", "  fs: 1e308")}}, gen,
       {"c.yaml:9: signal.fs", "valid range is [1000, 1e+09]"}},
      {"config: huge integer", {{"c.yaml", set_line(cfg, "order:", "  order: 99999999999999999999")}}, gen,
       {"c.yaml:12: filter.order", "is not an integer"}},
      {"config: alias bomb", {{"c.yaml", bomb}}, gen, {"c.yaml:", "alias bomb", "valid: at most 1000000"}},
      {"config: deep nesting", {{"c.yaml", deep}}, gen, {"c.yaml:1:", "nesting deeper than 64"}},
      {"config: second document", {{"c.yaml", cfg + "---\nname: x\n"}}, gen,
       {"c.yaml:", "second YAML document", "valid: one document"}},
      {"config: unknown key", {{"c.yaml", cfg + "colour: red\n"}}, gen, {"c.yaml:", "colour: unknown key"}},
      {"config: bad enum", {{"c.yaml", set_line(cfg, "overflow:", "  overflow: bogus")}}, gen,
       {"c.yaml:", "bandpass_fixed.overflow", "valid: wrap, saturate"}},
      {"config: syntax error", {{"c.yaml", "name: [unclosed\n"}}, gen, {"c.yaml:", "YAML syntax error"}},
      {"config: zero-length file", {{"c.yaml", ""}}, gen, {"c.yaml", "empty"}},
      {"config: a folder", {{"c.yaml", kDir}}, gen, {"c.yaml: is a folder; expected a configuration file"}},
      {"config: missing file", {}, gen, {"c.yaml", "no such file"}},
      // --- scene ---
      {"scene: duplicate key", {{"s.yaml", kScene + "  distances_m: [1.0]\n"}}, sim,
       {"s.yaml:4: geometry.distances_m: duplicate key", "first at {d}/s.yaml:3"}},
      {"scene: out of range", {{"s.yaml", kScene + "medium:\n  temperature_c: 100\n"}}, sim,
       {"s.yaml:5: medium.temperature_c", "valid range is [-40, 60]"}},
      {"scene: NaN as a string", {{"s.yaml", kScene + "medium:\n  temperature_c: \"NaN\"\n"}}, sim,
       {"s.yaml:5: medium.temperature_c", "not a finite number; valid range is [-40, 60]"}},
      {"scene: huge integer", {{"s.yaml", kScene + "noise:\n  adc:\n    bits: 1e400\n"}}, sim,
       {"s.yaml:6: noise.adc.bits", "valid range is [2, 24]"}},
      {"scene: non-UTF-8 byte", {{"s.yaml", "name: \xff\xfe\n" + kScene.substr(8)}}, sim,
       {"s.yaml:1:", "0xFF", "UTF-8"}},
      {"scene: zero-length file", {{"s.yaml", ""}}, sim, {"s.yaml", "empty"}},
      {"scene: a folder", {{"s.yaml", kDir}}, sim, {"s.yaml: is a folder; expected a scene file"}},
      {"scene: receiver config is a folder",
       {{"s.yaml", kScene + "receiver:\n  config: cfgdir\n"}, {"cfgdir", kDir}}, sim, {"cfgdir: is a folder"}},
      {"scene: empty references folder",
       {{"s.yaml", kScene + "receiver:\n  reference: files\n  references_dir: refs\n"}, {"refs", kDir}}, sim,
       {"refs: no reference for code 1", "Gold4-1.csv or .wav"}},
      {"scene: unknown metric", {{"s.yaml", kScene + "receiver:\n  metrics: [pearson, rho]\n"}}, sim,
       {"s.yaml:5: receiver.metrics", "metrics[1]: 'rho' is not valid; valid: pearson, energy, td"}},
      {"evaluate: a scene that computes no metric", {{"s.yaml", kScene + "receiver:\n  metrics: []\n"}},
       "evaluate {d}/s.yaml --quiet --no-plots --out {d}/ev", {"s.yaml: receiver.metrics", "[pearson, energy, td]"}},
      // --- outputs ---
      {"simulate --out is a file", {{"s.yaml", kScene}, {"out", "precious\n"}}, sim,
       {"option --out", "'{d}/out' exists and is not a folder"}},
      {"simulate --out /dev/full", {{"s.yaml", kScene}}, "simulate {d}/s.yaml --quiet --out /dev/full",
       {"option --out", "/dev/full", "not a folder"}},
      {"simulate --out under a file", {{"s.yaml", kScene}, {"f", "x"}}, "simulate {d}/s.yaml --quiet --out {d}/f/o",
       {"option --out", "Not a directory"}},
      {"simulate --out unwritable", {{"s.yaml", kScene}}, "simulate {d}/s.yaml --quiet --out /proc/ranging-test/o",
       {"option --out", "cannot create the folder '/proc/ranging-test/o'"}},
      {"evaluate --out is a file", {{"s.yaml", kScene}, {"out", "precious\n"}},
       "evaluate {d}/s.yaml --quiet --no-plots --out {d}/out", {"option --out", "not a folder"}},
      {"generate --out is a file", {{"c.yaml", cfg}, {"gen", "precious\n"}}, gen,
       {"option --out", "'{d}/gen' exists and is not a folder"}},
      {"stdout is /dev/full", {}, "codes --list", {"cannot write to standard output"}, "/dev/full"},
      // --- captures ---
      {"csv: Record Length beyond the rows", {{"x.csv", record_short}}, dec + "{d}/x.csv",
       {"x.csv:2: Record Length", "declares 80 rows, the file holds 50"}},
      {"csv: zero-length file", {{"x.csv", ""}}, dec + "{d}/x.csv", {"x.csv:", "no data rows"}},
      {"csv: NaN sample", {{"x.csv", "TIME,CH1\n0,0\n2e-7,nan\n4e-7,0\n"}}, dec + "{d}/x.csv",
       {"x.csv:3: voltage column", "not finite"}},
      {"csv: a folder", {{"x.csv", kDir}}, dec + "{d}/x.csv", {"x.csv: is a folder; expected a capture file"}},
      {"wav: data chunk past the end", {{"x.wav", wav_long}}, dec + "{d}/x.wav",
       {"x.wav: byte 36", "declares 4000 bytes, the file holds 100"}},
      {"wav: fmt chunk past the end", {{"x.wav", wav_fmt_long}}, dec + "{d}/x.wav", {"x.wav: byte 12", "fmt chunk"}},
      {"wav: zero-length file", {{"x.wav", ""}}, dec + "{d}/x.wav", {"x.wav: byte 0: empty file"}},
      {"wav: a scope's 1 GS/s, above the receiver's 500 MS/s", {{"x.wav", wav_capture(4000, 1e9)}}, dec + "{d}/x.wav",
       {"x.wav: sample rate 1000 MS/s is above what the receiver takes (500 MS/s)", "decimate"}},
      {"scene: sample_rate above 500 MS/s", {{"s.yaml", "sample_rate: 600000000\ngeometry:\n  distances_m: [0.5]\n"}},
       "simulate {d}/s.yaml --quiet", {"s.yaml:1: sample_rate: 600 MS/s is above what the receiver takes"}},
      {"wav: --channel the file lacks", {{"x.wav", wav_capture(50)}}, dec + "{d}/x.wav --channel 2",
       {"x.wav: byte 36: channel 2 is out of range", "valid 1..1"}},
      {"csv: --channel the rows lack", {{"x.csv", csv_capture(3000)}}, dec + "{d}/x.csv --channel 3",
       {"x.csv:", "channel 3 (column 4) is out of range", "valid 1..1"}},
      {"csv: one column without --sample-rate", {{"x.csv", "0.1\n0.2\n0.3\n"}}, dec + "{d}/x.csv",
       {"x.csv:1: expected 'time,voltage', found one column", "--sample-rate"}},
      {"csv: --sample-rate with a time column", {{"x.csv", csv_capture(3000)}}, dec + "{d}/x.csv --sample-rate 5e6",
       {"x.csv:", "a sample rate (5000000 Hz) was given, but the rows have a time column"}},
      {"decode --sample-rate out of range", {{"x.csv", csv_capture(3000)}}, dec + "{d}/x.csv --sample-rate 5",
       {"option --sample-rate", "5 is out of range; valid range is [10000, 1e+09]"}},
      {"capture: unknown type", {{"x.txt", "0,0\n"}}, dec + "{d}/x.txt", {"x.txt", "valid: .csv"}},
      {"decode --references a file", {{"x.csv", csv_capture(3000)}}, dec + "{d}/x.csv --references {d}/x.csv",
       {"x.csv: not a folder; expected the references folder"}},
      // --- UART byte captures (frames) ---
      {"frames: a folder", {{"u.bin", kDir}}, "frames {d}/u.bin", {"u.bin: is a folder; expected a byte capture"}},
      {"frames: missing file", {}, "frames {d}/u.bin", {"u.bin: cannot open the byte capture"}},
      {"decode: missing references folder", {{"x.csv", csv_capture(3000)}}, dec + "{d}/x.csv --references {d}/nope",
       {"nope: no such folder; expected the references folder"}},
  };
}

// Every path under dir (relative), with file contents, to compare before and after a run.
std::set<std::string> tree(const fs::path& dir) {
  std::set<std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    std::string entry = fs::relative(e.path(), dir).string();
    if (e.is_regular_file()) entry += "=" + slurp(e.path().string());
    out.insert(entry);
  }
  return out;
}

class BadInput : public ::testing::TestWithParam<Case> {};

TEST_P(BadInput, RefusedWithExit2AndNamedFieldAndNoOutput) {
  const Case& c = GetParam();
  const ranging::testing_support::ScratchDir scratch("ranging_bad");
  const fs::path dir = scratch.path();
  for (const auto& [name, content] : c.files) {
    if (content == kDir) {
      fs::create_directories(dir / name);
    } else {
      std::ofstream(dir / name, std::ios::binary) << content;
    }
  }
  const auto before = tree(dir);
  const std::string d = dir.string();
  std::string cmd = "cd \"" + d + "\" && \"" + RANGING_TOOL + "\" " + replace_all(c.args, "{d}", d);
  if (!c.redirect_stdout.empty()) cmd += " >" + c.redirect_stdout;
  const auto r = run_command(cmd);
  EXPECT_EQ(r.status, 2) << cmd << "\nstderr: " << r.err;
  EXPECT_EQ(r.out, "") << cmd;
  for (const auto& want : c.err) {
    EXPECT_NE(r.err.find(replace_all(want, "{d}", d)), std::string::npos)
        << "stderr lacks '" << replace_all(want, "{d}", d) << "'\nstderr: " << r.err;
  }
  EXPECT_EQ(tree(dir), before) << "the run created, changed or left files in " << d;
}

std::string case_name(const ::testing::TestParamInfo<Case>& info) {
  std::string n;
  for (char ch : info.param.name) n += std::isalnum(static_cast<unsigned char>(ch)) ? ch : '_';
  return n;
}

INSTANTIATE_TEST_SUITE_P(Catalogue, BadInput, ::testing::ValuesIn(catalogue()), case_name);

TEST(BadInputCatalogue, HasAtLeastFortyCases) { EXPECT_GE(catalogue().size(), 40u); }

// CRLF line endings and a UTF-8 BOM are accepted: the same output as the plain file.
TEST(BadInput, CrlfAndBomAreAccepted) {
  const ranging::testing_support::ScratchDir scratch("ranging_crlf");
  const fs::path dir = scratch.path();
  const std::string cfg = default_config();
  const std::string crlf = replace_all(cfg, "\n", "\r\n");
  const std::string bom = "\xEF\xBB\xBF";
  const std::vector<std::pair<std::string, std::string>> variants = {
      {"lf", cfg}, {"crlf", crlf}, {"bom", bom + cfg}, {"bomcrlf", bom + crlf}};
  std::string reference;
  for (const auto& [name, text] : variants) {
    std::ofstream(dir / (name + ".yaml"), std::ios::binary) << text;
    const auto r = run_command("\"" + std::string(RANGING_TOOL) + "\" demo --quiet --json --config \"" +
                               (dir / (name + ".yaml")).string() + "\"");
    EXPECT_EQ(r.status, 0) << name << ": " << r.err;
    EXPECT_FALSE(r.out.empty());
    if (reference.empty()) reference = r.out;
    EXPECT_EQ(r.out, reference) << name << " differs from the LF file";
  }
  // A scene: the measurements are the same.
  const std::string scene = "name: s\r\ngeometry:\r\n  distances_m: [0.3, 0.6]\r\n";
  std::string ref_csv;
  for (const auto& [name, text] :
       std::vector<std::pair<std::string, std::string>>{{"slf", replace_all(scene, "\r\n", "\n")},
                                                        {"scrlf", bom + scene}}) {
    std::ofstream(dir / (name + ".yaml"), std::ios::binary) << text;
    const auto r = run_command("\"" + std::string(RANGING_TOOL) + "\" simulate --quiet \"" +
                               (dir / (name + ".yaml")).string() + "\" --out \"" + (dir / name).string() + "\"");
    EXPECT_EQ(r.status, 0) << name << ": " << r.err;
    const std::string csv = slurp((dir / name / "measurements.csv").string());
    EXPECT_NE(csv.find("0.3"), std::string::npos);
    if (ref_csv.empty()) ref_csv = csv;
    EXPECT_EQ(csv, ref_csv) << name;
  }
}

// The shared writer: /dev/full is reported (ENOSPC) and written in place, never replaced by a
// file; a folder is refused; a successful write leaves no temporary beside the file.
TEST(AtomicFile, ReportsDiskFullAndLeavesNoTemporary) {
  try {
    ranging::write_file_atomic("/dev/full", "data");
    FAIL() << "no error writing /dev/full";
  } catch (const ranging::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/dev/full: cannot write"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("No space left"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(fs::is_character_file("/dev/full"));
  const ranging::testing_support::ScratchDir scratch("ranging_atomic");
  const fs::path dir = scratch.path();
  fs::create_directories(dir / "sub");
  EXPECT_THROW(ranging::write_file_atomic((dir / "sub").string(), "x"), ranging::InputError);
  EXPECT_THROW(ranging::write_file_atomic((dir / "missing" / "f").string(), "x"), ranging::InputError);
  ranging::write_file_atomic((dir / "f.txt").string(), "old");
  ranging::write_file_atomic((dir / "f.txt").string(), "new content");
  EXPECT_EQ(slurp((dir / "f.txt").string()), "new content");
  std::size_t entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++entries;
  EXPECT_EQ(entries, 2u);  // sub and f.txt: no temporary left
}

}  // namespace
