// Hostile NRRD input, one row per class: each is refused with one line that names the file
// and the problem, in bounded time, with no control character from the input, and the same
// way by the in-core reader (read_volume) and the streaming one (SliceReader). Files that
// are valid but unusual (data file patterns and lists, CR-only headers) read the same
// values both ways.
#include <doctest/doctest.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "clfractal/error.hpp"
#include "clfractal/slice_reader.hpp"
#include "clfractal/volume_io.hpp"
#include "bad_input_util.hpp"

using namespace clfractal;
namespace fs = std::filesystem;
using badinput::gzip;
using badinput::has_control;
using badinput::refusal;

namespace {

struct Folder {
    fs::path root;
    Folder() {
        root = fs::temp_directory_path() / ("clfractal_badinput_" + std::to_string(::getpid()));
        fs::remove_all(root);
        fs::create_directories(root);
    }
    ~Folder() {
        std::error_code ec;
        fs::remove_all(root, ec);
    }
    std::string put(const std::string& name, const std::string& bytes) const {
        const fs::path p = root / name;
        fs::create_directories(p.parent_path());
        std::ofstream(p, std::ios::binary) << bytes;
        return p.string();
    }
};

std::string header(const std::string& sizes, const std::string& encoding, const std::string& extra = "") {
    return "NRRD0004\ntype: uchar\ndimension: 3\nsizes: " + sizes + "\nencoding: " + encoding + "\n" + extra;
}

/// Every value of a volume read slice by slice.
std::vector<unsigned char> streamed(const std::string& path) {
    SliceReader r(path);
    std::vector<unsigned char> v(r.slice_bytes() * r.dims().nz);
    r.read(v.data(), r.dims().nz);
    return v;
}

std::vector<unsigned char> in_core(const std::string& path) {
    const Volume v = read_volume(path);
    const auto* p = static_cast<const unsigned char*>(v.data());
    return std::vector<unsigned char>(p, p + v.size_bytes());
}

std::string ramp(std::size_t n, int seed = 0) {
    std::string s(n, '\0');
    for (std::size_t i = 0; i < n; ++i) s[i] = char((i * 7 + std::size_t(seed) * 13) % 251);
    return s;
}

}  // namespace

TEST_SUITE("badinput") {

TEST_CASE("every class of hostile NRRD input: one line naming the file, both read paths alike, fast") {
    Folder dir;
    ::mkfifo((dir.root / "fifo.raw").c_str(), 0600);
    fs::create_directories(dir.root / "folder.raw");
    std::string long_folder = "";
    for (int i = 0; i < 5; ++i) long_folder += std::string(200, char('a' + i)) + "/";

    struct Row {
        const char* what;
        std::string name, content, reason;
    };
    std::string kv;
    for (int i = 0; i < 100000; ++i) kv += "k" + std::to_string(i) + ":=v\n";
    std::string big_kv;
    for (int i = 0; i < 200; ++i) big_kv += "k" + std::to_string(i) + ":=" + std::string(8000, 'x') + "\n";
    const std::string zlib_data = gzip(ramp(64), 15);  // zlib, not gzip
    const std::string tiny_gzip = gzip(std::string(16, '\0'));
    const std::vector<Row> rows = {
        {"oversized header", "big_header.nrrd", header("2 2 2", "raw", big_kv) + "\n" + ramp(8),
         "header is longer than 1 MiB"},
        {"long field line (a 1 MB sizes value)", "long_sizes.nrrd",
         "NRRD0004\ntype: uchar\ndimension: 3\nsizes: " + std::string(1 << 20, '7') + "\nencoding: raw\n\n",
         "is longer than"},
        {"long data file name", "long_name.nhdr", header("2 2 2", "raw", "data file: " + std::string(950, 'n') + ".raw\n"),
         "longer than"},
        {"1000 space directions", "directions.nrrd",
         header("2 2 2", "raw", "space dimension: 3\nspace directions:" + [] {
             std::string s;
             for (int i = 0; i < 1000; ++i) s += " (1,0,0)";
             return s;
         }() + "\n") + "\n" + ramp(8),
         "longer than"},
        {"four space directions for three axes", "directions4.nrrd",
         header("2 2 2", "raw", "space dimension: 3\nspace directions: (1,0,0) (0,1,0) (0,0,1) (1,1,1)\n") + "\n" +
             ramp(8),
         "must give 3 vectors"},
        {"absurd sizes", "absurd.nrrd", header("100000 100000 100000", "raw") + "\n" + ramp(8),
         "exceed the maximum of 2^40 values"},
        {"negative size", "negative.nrrd", header("2 -2 2", "raw") + "\n" + ramp(8), "positive integer"},
        {"sizes vs dimension", "sizes2.nrrd", header("2 2", "raw") + "\n" + ramp(8), "must give 3 axis sizes"},
        {"size vs file: 74 bytes claiming 8 GiB", "claim.nrrd", header("2147483648 2 2", "raw") + "\n",
         "truncated: the header claims 8589934592 bytes"},
        {"gzip bomb claim: a tiny gzip claiming 10^12 values", "bomb.nrrd",
         header("10000 10000 10000", "gzip") + "\n" + tiny_gzip, "cannot hold the 1000000000000 bytes"},
        {"zlib data declared gzip", "zlib.nrrd", header("4 4 4", "gzip") + "\n" + zlib_data,
         "declared gzip but is not gzip"},
        {"FIFO as data file", "fifo.nhdr", header("2 2 2", "raw", "data file: fifo.raw\n"), "not a regular file"},
        {"folder as data file", "folder.nhdr", header("2 2 2", "raw", "data file: folder.raw\n"), "not a regular file"},
        {"missing data file", "missing.nhdr", header("2 2 2", "raw", "data file: nope.raw\n"), "does not exist"},
        {"100,000 key/value lines", "kv.nrrd", header("2 2 2", "raw", kv) + "\n" + ramp(8),
         "more than 1000 comment and key:=value lines"},
        {"bad data file pattern", "pattern.nhdr", header("2 2 2", "raw", "data file: s%d%d.raw 0 1 1\n"),
         "is not 'FORMAT MIN MAX STEP [SUBDIM]'"},
        {"pattern naming 10^9 files", "pattern_many.nhdr", header("2 2 2", "raw", "data file: s%d.raw 0 999999999 1\n"),
         "names more than 65536 files"},
        {"empty LIST", "list.nhdr", header("2 2 2", "raw", "data file: LIST\n"), "followed by no file names"},
        {"no magic", "magic.nrrd", "hello\n", "not a NRRD file"},
        {"unknown field", "field.nrrd", header("2 2 2", "raw", "colour: red\n") + "\n" + ramp(8),
         "unknown header field 'colour'"},
        {"duplicate field", "dup.nrrd", header("2 2 2", "raw", "encoding: raw\n") + "\n" + ramp(8), "appears twice"},
        {"bzip2", "bz.nrrd", header("2 2 2", "bzip2") + "\n" + ramp(8), "bzip2 encoding is not supported"},
        {"no blank line before attached data", "noblank.nrrd", header("2 2 2", "raw"), "no blank line"},
        {"control characters in the input", "ctl.nrrd", header("2 2 2", "raw", "type\x1b[31m: x\n") + "\n" + ramp(8),
         "header line 'type' contains the control byte 0x1b"},
        {"control characters in the type", "ctl2.nrrd",
         "NRRD0004\ntype: \x1b]0;owned\x07\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n\n" + ramp(8),
         "header line 'type: ' contains the control byte 0x1b"},
        {"control characters in the file name", "name\x1b]0;owned\x07.nrrd", "hello\n", "not a NRRD file"},
        {"NUL in a LIST line (teem overran its line buffer)", "nul.nrrd",
         header("4 2 2", "raw", "data file: LIST\nd0.raw\nd1.raw") + std::string("\0\0\0\xee", 4) + "AT\n",
         "contains the control byte 0x00"},
        {"malformed NRRD at a path of 1000+ characters", long_folder + "x.nrrd", "hello\n",
         "longer than the NRRD reader's limit of 400"},
    };
    for (const Row& row : rows) {
        CAPTURE(row.what);
        const std::string path = dir.put(row.name, row.content);
        const auto t0 = std::chrono::steady_clock::now();
        const std::string core = refusal([&] { read_volume(path); });
        const std::string stream = refusal([&] { SliceReader r(path); });
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        CHECK_MESSAGE(core.find(row.reason) != std::string::npos, core);
        CHECK(core.rfind(printable(path) + ": ", 0) == 0);  // names the file first
        CHECK(core.find('\n') == std::string::npos);
        CHECK_FALSE(has_control(core));
        CHECK(stream == core);
        CHECK(seconds < 2.0);
    }
}

TEST_CASE("data file patterns, lists and CR-only headers: the same values in core and streamed") {
    Folder dir;
    const std::string a = ramp(12, 1), b = ramp(12, 2), c = ramp(12, 3);
    dir.put("s0.raw", a);
    dir.put("s1.raw", b);
    dir.put("s2.raw", c);
    dir.put("s3.raw", ramp(12, 4));
    dir.put("s003.raw", a);
    dir.put("s005.raw", b);
    const std::string all = a + b + c;
    struct Row {
        const char* what;
        std::string name, content, expected;
    };
    const std::vector<Row> rows = {
        {"pattern s%d.raw 0 2 1", "pattern.nhdr", header("4 3 3", "raw", "data file: s%d.raw 0 2 1 2\n"), all},
        {"pattern with width and step", "pattern2.nhdr", header("4 3 2", "raw", "data file: s%03d.raw 3 5 2\n"), a + b},
        {"descending pattern", "pattern3.nhdr", header("4 3 3", "raw", "data file: s%d.raw 2 0 -1\n"), c + b + a},
        {"LIST", "list.nhdr", header("4 3 3", "raw", "data file: LIST\ns2.raw\ns0.raw\ns1.raw\n"), c + a + b},
        {"single detached file", "single.nhdr", header("4 3 1", "raw", "data file: s1.raw\n"), b},
        {"CR-only header", "cr.nrrd",
         "NRRD0004\rtype: uchar\rdimension: 3\rsizes: 4 3 3\rencoding: raw\r\r" + all, all},
        {"CRLF header", "crlf.nrrd",
         "NRRD0004\r\ntype: uchar\r\ndimension: 3\r\nsizes: 4 3 3\r\nencoding: raw\r\n\r\n" + all, all},
        {"CR-only header, gzip data", "cr_gz.nrrd",
         "NRRD0004\rtype: uchar\rdimension: 3\rsizes: 4 3 3\rencoding: gzip\r\r" + gzip(all), all},
    };
    for (const Row& row : rows) {
        CAPTURE(row.what);
        const std::string path = dir.put(row.name, row.content);
        const std::vector<unsigned char> expected(row.expected.begin(), row.expected.end());
        CHECK(in_core(path) == expected);
        CHECK(streamed(path) == expected);
    }
}

}  // TEST_SUITE
