// The bounded NRRD pre-parse (see nrrd_guard.hpp). Field names and forms follow the NRRD
// file format, version 5 (teem's nrrd/format.html).
#include "io/nrrd_guard.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <sstream>

#include <teem/nrrd.h>
#include <zlib.h>

#include "clfractal/error.hpp"
#include "clfractal/volume.hpp"

namespace fs = std::filesystem;

namespace clfractal {

namespace {

std::string lower(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return s;
}

std::string trim(const std::string& s) {
    std::size_t a = 0, b = s.size();
    while (a < b && std::isspace(static_cast<unsigned char>(s[a]))) ++a;
    while (b > a && std::isspace(static_cast<unsigned char>(s[b - 1]))) --b;
    return s.substr(a, b - a);
}

std::vector<std::string> words(const std::string& s) {
    std::istringstream in(s);
    std::vector<std::string> w;
    for (std::string t; in >> t;) w.push_back(t);
    return w;
}

/// A quote of input for a message: printable and short.
std::string quote(const std::string& s) {
    const std::size_t keep = 60;
    return "'" + printable(s.size() > keep ? s.substr(0, keep) + "..." : s) + "'";
}

template <class T> bool parse_int(const std::string& s, T& value) {
    const char* first = s.data();
    const char* last = first + s.size();
    const auto [next, ec] = std::from_chars(first, last, value);
    return first != last && ec == std::errc() && next == last;
}

/// teem's type names (case-insensitive) -> canonical name and bytes per value.
bool nrrd_type(const std::string& text, std::string& name, std::size_t& bytes) {
    static const std::map<std::string, std::pair<const char*, std::size_t>> types = {
        {"signed char", {"char", 1}}, {"int8", {"char", 1}}, {"int8_t", {"char", 1}},
        {"uchar", {"uchar", 1}}, {"unsigned char", {"uchar", 1}}, {"uint8", {"uchar", 1}},
        {"uint8_t", {"uchar", 1}}, {"short", {"short", 2}}, {"short int", {"short", 2}},
        {"signed short", {"short", 2}}, {"signed short int", {"short", 2}}, {"int16", {"short", 2}},
        {"int16_t", {"short", 2}}, {"ushort", {"ushort", 2}}, {"unsigned short", {"ushort", 2}},
        {"unsigned short int", {"ushort", 2}}, {"uint16", {"ushort", 2}}, {"uint16_t", {"ushort", 2}},
        {"int", {"int", 4}}, {"signed int", {"int", 4}}, {"int32", {"int", 4}}, {"int32_t", {"int", 4}},
        {"uint", {"uint", 4}}, {"unsigned int", {"uint", 4}}, {"uint32", {"uint", 4}},
        {"uint32_t", {"uint", 4}}, {"longlong", {"longlong", 8}}, {"long long", {"longlong", 8}},
        {"long long int", {"longlong", 8}}, {"signed long long", {"longlong", 8}},
        {"signed long long int", {"longlong", 8}}, {"int64", {"longlong", 8}}, {"int64_t", {"longlong", 8}},
        {"ulonglong", {"ulonglong", 8}}, {"unsigned long long", {"ulonglong", 8}},
        {"unsigned long long int", {"ulonglong", 8}}, {"uint64", {"ulonglong", 8}},
        {"uint64_t", {"ulonglong", 8}}, {"float", {"float", 4}}, {"double", {"double", 8}}};
    const auto it = types.find(lower(text));
    if (it == types.end()) return false;
    name = it->second.first;
    bytes = it->second.second;
    return true;
}

bool known_field(const std::string& f) {
    static const char* fields[] = {
        "content", "number", "type", "block size", "blocksize", "dimension", "space", "space dimension",
        "sizes", "spacings", "thicknesses", "axis mins", "axismins", "axis maxs", "axismaxs", "centers",
        "centerings", "kinds", "labels", "units", "min", "max", "old min", "oldmin", "old max", "oldmax",
        "endian", "encoding", "line skip", "lineskip", "byte skip", "byteskip", "sample units", "sampleunits",
        "space units", "space origin", "space directions", "measurement frame", "data file", "datafile"};
    for (const char* name : fields)
        if (f == name) return true;
    return false;
}

/// One %d-like conversion (flags 0 or -, a width, then d, i or u) and no other bare '%'.
bool expand_pattern(const std::string& format, long long i, std::string& out) {
    out.clear();
    bool converted = false;
    for (std::size_t k = 0; k < format.size(); ++k) {
        if (format[k] != '%') {
            out += format[k];
            continue;
        }
        if (k + 1 < format.size() && format[k + 1] == '%') {
            out += '%';
            ++k;
            continue;
        }
        if (converted) return false;
        std::size_t j = k + 1;
        bool zero = false;
        while (j < format.size() && (format[j] == '0' || format[j] == '-')) zero |= format[j++] == '0';
        std::size_t width = 0;
        while (j < format.size() && std::isdigit(static_cast<unsigned char>(format[j])) && width < 100)
            width = width * 10 + std::size_t(format[j++] - '0');
        if (j >= format.size() || (format[j] != 'd' && format[j] != 'i' && format[j] != 'u') || width > 32)
            return false;
        std::string digits = std::to_string(i < 0 ? -i : i);
        const std::size_t sign = i < 0 ? 1 : 0;
        if (zero) digits.insert(0, width > digits.size() + sign ? width - digits.size() - sign : 0, '0');
        digits.insert(0, sign, '-');
        if (!zero) digits.insert(0, width > digits.size() ? width - digits.size() : 0, ' ');
        out += digits;
        converted = true;
        k = j;
    }
    return converted;
}

struct Stat {
    bool exists = false, regular = false;
    std::uint64_t size = 0;
};

Stat stat_of(const std::string& p) {
    struct stat st {};
    Stat s;
    if (::stat(p.c_str(), &st) != 0) return s;
    s.exists = true;
    s.regular = S_ISREG(st.st_mode);
    s.size = std::uint64_t(st.st_size);
    return s;
}

/// The header bytes (at most NrrdLimits::header_bytes + 1) of a regular file.
std::string read_head(const std::string& path) {
    const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) throw InputError(printable(path) + ": cannot open: " + std::strerror(errno));
    struct stat st {};
    if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        ::close(fd);
        throw InputError(printable(path) + ": not a regular file");
    }
    std::string head(std::min<std::uint64_t>(std::uint64_t(st.st_size), NrrdLimits::header_bytes + 1), '\0');
    std::size_t got = 0;
    while (got < head.size()) {
        const ssize_t n = ::read(fd, head.data() + got, head.size() - got);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) break;
        got += std::size_t(n);
    }
    ::close(fd);
    head.resize(got);
    return head;
}

/// The first bytes of `path` from `offset` on.
std::string peek(const std::string& path, std::uint64_t offset, std::size_t count) {
    const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) return {};
    std::string bytes(count, '\0');
    const ssize_t n = ::pread(fd, bytes.data(), count, off_t(offset));
    ::close(fd);
    bytes.resize(n > 0 ? std::size_t(n) : 0);
    return bytes;
}

/// Makes the error for one problem of the named file.
struct Fail {
    std::string name;
    InputError operator()(const std::string& problem) const { return InputError(name + ": " + problem); }
};

/// The header's lines, read one at a time from `head`. Lines end in \n, \r\n or \r (as teem
/// reads them).
struct HeaderLines {
    const std::string& head;
    const Fail& fail;
    std::size_t pos = 0;
    bool ended = false;  // a blank line ended the header

    bool next(std::string& line, std::size_t limit) {
        if (pos >= head.size()) return false;
        std::size_t end = pos;
        while (end < head.size() && head[end] != '\n' && head[end] != '\r') {
            if (end - pos >= limit)
                throw fail("header line " + quote(head.substr(pos, 40)) + " is longer than " +
                           std::to_string(limit) + " characters");
            // teem's line reader overruns its buffer on a NUL; no header needs control bytes.
            const unsigned char c = static_cast<unsigned char>(head[end]);
            if ((c < 0x20 && c != '\t') || c == 0x7f) {
                char code[8];
                std::snprintf(code, sizeof code, "0x%02x", c);
                throw fail("header line " + quote(head.substr(pos, end - pos)) + " contains the control byte " + code);
            }
            ++end;
        }
        if (end >= head.size() && head.size() > NrrdLimits::header_bytes)
            throw fail("header is longer than " + std::to_string(NrrdLimits::header_bytes >> 20) + " MiB");
        line = head.substr(pos, end - pos);
        pos = end;
        if (pos < head.size()) pos += (head[pos] == '\r' && pos + 1 < head.size() && head[pos + 1] == '\n') ? 2 : 1;
        return true;
    }
};

/// What the field lines have set so far, beyond the header itself.
struct FieldState {
    bool have_type = false, have_sizes = false, have_encoding = false, list_files = false;
    std::size_t key_values = 0;
    std::vector<std::string> seen;
    std::string data_file_text;
};

/// The "sizes" field: one positive size per axis, at most 2^40 values in all.
void parse_sizes(const std::string& value, NrrdHeader& h, const Fail& fail) {
    if (!h.dimension) throw fail("'sizes' comes before 'dimension'");
    const std::vector<std::string> w = words(value);
    if (w.size() != h.dimension)
        throw fail("sizes " + quote(value) + " must give " + std::to_string(h.dimension) + " axis sizes");
    std::uint64_t product = 1;
    for (const std::string& s : w) {
        std::size_t n = 0;
        if (!parse_int(s, n) || n < 1) throw fail("sizes " + quote(value) + ": each must be a positive integer");
        if (n > max_vertices || product > max_vertices / n)
            throw fail("sizes " + quote(value) + " exceed the maximum of 2^40 values");
        product *= n;
        h.sizes.push_back(n);
    }
}

/// The "encoding" field, by its canonical name.
void parse_encoding(const std::string& value, NrrdHeader& h, const Fail& fail) {
    const std::string e = lower(value);
    if (e == "raw") h.encoding = "raw";
    else if (e == "gzip" || e == "gz") h.encoding = "gzip";
    else if (e == "ascii" || e == "text" || e == "txt") h.encoding = "ascii";
    else if (e == "hex") h.encoding = "hex";
    else if (e == "bzip2" || e == "bz2") throw fail("bzip2 encoding is not supported (use raw or gzip)");
    else throw fail("unknown encoding " + quote(value));
}

/// The "space directions" field: one vector or 'none' per axis.
void check_space_directions(const std::string& value, const NrrdHeader& h, const Fail& fail) {
    if (!h.dimension) throw fail("'space directions' comes before 'dimension'");
    std::size_t vectors = 0, depth = 0;
    for (const std::string& w : words(value)) {
        if (w == "none") {
            ++vectors;
            continue;
        }
        for (char c : w) {
            if (c == '(') ++depth;
            if (c == ')' && depth-- == 0) depth = 99;
        }
        if (depth == 0) ++vectors;
        if (depth > 1) break;
    }
    if (depth != 0 || vectors != h.dimension)
        throw fail("space directions " + quote(value) + " must give " + std::to_string(h.dimension) +
                   " vectors or 'none'");
}

/// The "data file" field: one file, a pattern of files, or LIST (the names follow).
void parse_data_file(const std::string& value, NrrdHeader& h, FieldState& st, const Fail& fail) {
    st.data_file_text = value;
    const std::vector<std::string> w = words(value);
    if (value.empty()) throw fail("'data file' names no file");
    if (w[0] == "LIST") {
        st.list_files = true;
    } else if (w.size() >= 4 && w.size() <= 5 && w[0].find('%') != std::string::npos) {
        long long first = 0, last = 0, step = 0;
        std::string file;
        const long long bound = 1000000000;
        if (!parse_int(w[1], first) || !parse_int(w[2], last) || !parse_int(w[3], step) || step == 0 ||
            std::max({std::llabs(first), std::llabs(last), std::llabs(step)}) > bound ||
            (last - first) / step < 0 || !expand_pattern(w[0], first, file))
            throw fail("data file pattern " + quote(value) + " is not 'FORMAT MIN MAX STEP [SUBDIM]'");
        const long long count = (last - first) / step + 1;
        if (count > static_cast<long long>(NrrdLimits::data_files))
            throw fail("data file pattern " + quote(value) + " names more than " +
                       std::to_string(NrrdLimits::data_files) + " files");
        for (long long i = first; step > 0 ? i <= last : i >= last; i += step) {
            expand_pattern(w[0], i, file);
            h.data_files.push_back(file);
        }
    } else {
        h.data_files.push_back(value);
    }
}

/// One known field's value, checked and stored in h.
void parse_field(const std::string& field, const std::string& value, NrrdHeader& h, FieldState& st,
                 const Fail& fail) {
    if (field == "dimension") {
        if (!parse_int(value, h.dimension) || h.dimension < 1 || h.dimension > 16)
            throw fail("dimension " + quote(value) + " must be an integer from 1 to 16");
    } else if (field == "type") {
        if (!nrrd_type(value, h.type, h.value_bytes))
            throw fail("unknown NRRD type " + quote(value) +
                       (lower(value) == "block" ? " (block data is not a scalar volume)" : ""));
        st.have_type = true;
    } else if (field == "sizes") {
        parse_sizes(value, h, fail);
        st.have_sizes = true;
    } else if (field == "encoding") {
        parse_encoding(value, h, fail);
        st.have_encoding = true;
    } else if (field == "endian") {
        const std::string e = lower(value);
        if (e != "little" && e != "big") throw fail("endian " + quote(value) + " must be little or big");
        h.big_endian = e == "big";
    } else if (field == "line skip" || field == "lineskip") {
        if (!parse_int(value, h.line_skip) || h.line_skip < 0 || h.line_skip > 1000000)
            throw fail("line skip " + quote(value) + " must be an integer from 0 to 10^6");
    } else if (field == "byte skip" || field == "byteskip") {
        if (!parse_int(value, h.byte_skip) || h.byte_skip < -1 || h.byte_skip > (1ll << 40))
            throw fail("byte skip " + quote(value) + " must be -1 or a non-negative integer");
    } else if (field == "space directions") {
        check_space_directions(value, h, fail);
    } else if (field == "data file" || field == "datafile") {
        parse_data_file(value, h, st, fail);
    }
}

/// The lines after the magic up to the blank line (or the end): fields, comments,
/// key:=value lines and listed data files; then the fields every header needs.
void read_fields(HeaderLines& lines, NrrdHeader& h, const Fail& fail) {
    FieldState st;
    std::string line;
    while (lines.next(line, st.list_files ? NrrdLimits::path : NrrdLimits::key_value_line)) {
        if (line.empty()) {
            lines.ended = true;
            break;
        }
        if (st.list_files) {
            h.data_files.push_back(line);
            if (h.data_files.size() > NrrdLimits::data_files)
                throw fail("more than " + std::to_string(NrrdLimits::data_files) + " data files");
            continue;
        }
        const std::size_t kv = line.find(":="), colon = line.find(": ");
        if (line[0] == '#' || (kv != std::string::npos && (colon == std::string::npos || kv < colon))) {
            if (++st.key_values > NrrdLimits::key_values)
                throw fail("more than " + std::to_string(NrrdLimits::key_values) + " comment and key:=value lines");
            continue;
        }
        if (line.size() > NrrdLimits::field_line)
            throw fail("header field " + quote(line) + " is longer than " + std::to_string(NrrdLimits::field_line) +
                       " characters");
        if (colon == std::string::npos) throw fail("header line " + quote(line) + " is not 'field: value'");
        const std::string field = lower(line.substr(0, colon));
        const std::string value = trim(line.substr(colon + 2));
        if (!known_field(field)) throw fail("unknown header field " + quote(field));
        if (std::find(st.seen.begin(), st.seen.end(), field) != st.seen.end())
            throw fail("header field " + quote(field) + " appears twice");
        st.seen.push_back(field);
        parse_field(field, value, h, st, fail);
    }
    if (lines.pos >= lines.head.size() && lines.head.size() > NrrdLimits::header_bytes)
        throw fail("header is longer than " + std::to_string(NrrdLimits::header_bytes >> 20) + " MiB");
    if (!st.have_type) throw fail("header has no 'type' field");
    if (!h.dimension) throw fail("header has no 'dimension' field");
    if (!st.have_sizes) throw fail("header has no 'sizes' field");
    if (!st.have_encoding) throw fail("header has no 'encoding' field");
    if (st.list_files && h.data_files.empty()) throw fail("'data file: LIST' is followed by no file names");
}

/// Attached data (after the header of `path`) or detached files, relative to its folder.
void place_data(NrrdHeader& h, const std::string& path, const HeaderLines& lines, const Fail& fail) {
    h.attached = h.data_files.empty();
    if (h.attached) {
        if (!lines.ended) throw fail("header has no blank line before the data");
        h.data_offset = lines.pos;
        h.data_files.push_back(path);
    } else {
        const fs::path folder = fs::path(path).parent_path();
        for (std::string& f : h.data_files) {
            fs::path p(f);
            if (p.is_relative()) p = folder / p;
            f = p.string();
            if (f.size() > NrrdLimits::path)
                throw fail("data file path of " + std::to_string(f.size()) +
                           " characters is longer than the NRRD reader's limit of " + std::to_string(NrrdLimits::path));
        }
    }
}

/// The bytes the data files hold after the data offset; each must be a regular file, and
/// gzip data must start with the gzip magic.
std::uint64_t data_available(const NrrdHeader& h, const std::string& path, const Stat& header_stat,
                             const Fail& fail) {
    std::uint64_t available = 0;
    for (const std::string& f : h.data_files) {
        const Stat s = f == path ? header_stat : stat_of(f);
        if (!s.exists) throw fail("data file " + quote(f) + " does not exist");
        if (!s.regular) throw fail("data file " + quote(f) + " is not a regular file");
        const std::uint64_t start = h.attached ? h.data_offset : 0;
        available += s.size > start ? s.size - start : 0;
        if (h.encoding == "gzip" && h.line_skip == 0 && h.byte_skip == 0) {
            const std::string magic = peek(f, start, 2);
            if (magic.size() < 2 || static_cast<unsigned char>(magic[0]) != 0x1f ||
                static_cast<unsigned char>(magic[1]) != 0x8b)
                throw fail(std::string(h.attached ? "data" : "data file " + quote(f)) +
                           " is declared gzip but is not gzip (no gzip header)");
        }
    }
    return available;
}

/// The data the header implies, against the `available` bytes, by encoding.
void check_data_claim(const NrrdHeader& h, std::uint64_t available, const Fail& fail) {
    const std::uint64_t bytes = h.values() * h.value_bytes;
    const std::string claim = std::to_string(bytes) + " bytes (" + std::to_string(h.values()) + " values of " +
                              h.type + ")";
    if (h.encoding == "raw") {
        const std::uint64_t skips = std::uint64_t(std::max(0ll, h.byte_skip) + h.line_skip) * h.data_files.size();
        if (available < bytes + skips)
            throw fail("truncated: the header claims " + claim + " of raw data, the file" +
                       (h.data_files.size() > 1 ? "s hold " : " holds ") + std::to_string(available));
    } else if (h.encoding == "gzip") {
        if (available * NrrdLimits::deflate_ratio < bytes)
            throw fail("gzip data of " + std::to_string(available) + " bytes cannot hold the " + claim +
                       " the header claims");
    } else if (h.encoding == "ascii") {
        if (available < h.values()) throw fail("truncated: the header claims " + claim + " as text, the data holds " +
                                               std::to_string(available) + " characters");
    } else if (h.encoding == "hex") {
        if (available < 2 * bytes) throw fail("truncated: the header claims " + claim + " as hex, the data holds " +
                                              std::to_string(available) + " characters");
    }
}

}  // namespace

std::uint64_t NrrdHeader::values() const {
    std::uint64_t n = 1;
    for (std::size_t s : sizes) n *= s;  // bounded by check_nrrd (at most 2^40)
    return n;
}

NrrdHeader check_nrrd(const std::string& path) {
    // teem prints warnings to stderr unless told not to; the library never prints.
    static const bool quiet_teem = (nrrdStateVerboseIO = 0, true);
    (void)quiet_teem;
    const Fail fail{printable(path)};
    if (path.size() > NrrdLimits::path)
        throw fail("path of " + std::to_string(path.size()) + " characters is longer than the NRRD reader's limit of " +
                   std::to_string(NrrdLimits::path));
    const std::string head = read_head(path);
    const Stat header_stat = stat_of(path);

    HeaderLines lines{head, fail};
    std::string line;
    if (!lines.next(line, 64) || line.compare(0, 6, "NRRD00") != 0 || line.size() != 8 || line[6] != '0' ||
        line[7] < '1' || line[7] > '5')
        throw fail("not a NRRD file (no NRRD0001..NRRD0005 magic on the first line)");

    NrrdHeader h;
    read_fields(lines, h, fail);
    place_data(h, path, lines, fail);
    // The data the header implies, against what the files hold.
    check_data_claim(h, data_available(h, path, header_stat, fail), fail);
    return h;
}

void read_gzip_data(const std::string& file, std::uint64_t offset, void* dst, std::uint64_t bytes,
                    const std::string& name) {
    const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) throw InputError(printable(name) + ": cannot open: " + std::strerror(errno));
    if (::lseek(fd, off_t(offset), SEEK_SET) < 0) {
        ::close(fd);
        throw InputError(printable(name) + ": cannot seek to the data");
    }
    gzFile gz = gzdopen(fd, "rb");
    if (!gz) {
        ::close(fd);
        throw InputError(printable(name) + ": cannot open the gzip stream");
    }
    auto* out = static_cast<unsigned char*>(dst);
    std::uint64_t done = 0;
    std::string problem;
    while (done < bytes && problem.empty()) {
        const unsigned chunk = unsigned(std::min<std::uint64_t>(bytes - done, 1u << 30));
        const int got = gzread(gz, out + done, chunk);
        if (gzdirect(gz)) problem = "the data is not gzip-compressed";
        else if (got < 0) {
            int code = Z_OK;
            problem = std::string("gzip data corrupt: ") + gzerror(gz, &code);
        } else if (got == 0) problem = "gzip data truncated: " + std::to_string(done) + " of " + std::to_string(bytes) + " bytes";
        else done += std::uint64_t(got);
    }
    gzclose(gz);
    if (!problem.empty()) throw InputError(printable(name) + ": " + problem);
}

}  // namespace clfractal
