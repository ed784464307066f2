// DICOM series through GDCM: a directory (or one file of it) is one volume. Headers are
// read with gdcm::Scanner, slices sorted by position along the slice normal (as GDCM's
// IPPSorter does) and checked for even spacing, pixels decoded with gdcm::ImageReader (every
// transfer syntax GDCM decodes), values in modality units by the rescale rule
// (docs/definitions.md §27 "Values and orientation"). Built as the module clfractal_dicom,
// loaded on first use by io/dicom_loader.cpp: its one export is clfractal_dicom_module().
#include "io/dicom_module.hpp"

#include <gdcmDirectory.h>
#include <gdcmImage.h>
#include <gdcmImageReader.h>
#include <gdcmScanner.h>
#include <gdcmTrace.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>

#include "io/input_guard.hpp"

namespace fs = std::filesystem;

namespace clfractal::io {
namespace {

const gdcm::Tag tag_series_uid(0x0020, 0x000e), tag_position(0x0020, 0x0032), tag_orientation(0x0020, 0x0037),
    tag_pixel_spacing(0x0028, 0x0030), tag_rows(0x0028, 0x0010), tag_columns(0x0028, 0x0011),
    tag_slope(0x0028, 0x1053), tag_intercept(0x0028, 0x1052), tag_description(0x0008, 0x103e),
    tag_frames(0x0028, 0x0008), tag_thickness(0x0018, 0x0050), tag_bits(0x0028, 0x0100),
    tag_samples(0x0028, 0x0002), tag_bits_stored(0x0028, 0x0101), tag_high_bit(0x0028, 0x0102),
    tag_photometric(0x0028, 0x0004);

std::vector<double> numbers(const char* text) {
    std::vector<double> v;
    if (!text) return v;
    std::string s(text);
    std::replace(s.begin(), s.end(), '\\', ' ');
    std::istringstream in(s);
    double x;
    while (in >> x) v.push_back(x);
    return v;
}

std::string trimmed(const char* text) {
    std::string s = text ? text : "";
    while (!s.empty() && (s.back() == ' ' || s.back() == '\0')) s.pop_back();
    return s;
}

std::string name_of(const std::string& file) { return fs::path(file).filename().string(); }

struct Slice {
    std::string file;
    double position = 0;  // along the slice normal
    Rescale map;
};

struct Series {
    std::string uid, description;
    std::vector<std::string> files;
    std::size_t rows = 0, columns = 0;
};

/// Where a file's pixel data lies, as the walk over its elements found it.
struct Layout {
    enum Kind { native, encapsulated, deflated, unknown } kind = unknown;
    std::uint64_t pixel_bytes = 0;  ///< native: the element's length; otherwise what may hold it
};

/// The headers of every DICOM file of a directory, grouped by series.
struct Scan {
    std::map<std::string, Layout> layouts;
    std::string dir;
    gdcm::Scanner scanner;
    std::map<std::string, Series> series;
    std::string selected;  // the file given, when a single file was named
};

bool dicom_extension(const std::string& file) {
    std::string ext = fs::path(file).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return ext == ".dcm" || ext == ".dicom" || ext == ".ima";
}

void quiet_gdcm() {
    gdcm::Trace::SetDebug(false);
    gdcm::Trace::SetWarning(false);
    gdcm::Trace::SetError(false);
}

enum class Walk { complete, truncated, no_preamble, bad_vr, bad_meta, bad_recognition, bad_overlay };

/// A DICOM file read a few bytes at a time into h.
struct ElementReader {
    explicit ElementReader(const std::string& file) : in(file, std::ios::binary) {}
    bool read_at(std::uint64_t at, std::size_t n) {
        in.clear();
        in.seekg(std::streamoff(at));
        return bool(in.read(reinterpret_cast<char*>(h), std::streamsize(n)));
    }
    unsigned u16(int at, bool big) const { return big ? unsigned(h[at] << 8 | h[at + 1]) : unsigned(h[at] | h[at + 1] << 8); }
    std::uint32_t u32(int at, bool big) const {
        return big ? std::uint32_t(h[at]) << 24 | std::uint32_t(h[at + 1]) << 16 | std::uint32_t(h[at + 2]) << 8 | h[at + 3]
                   : std::uint32_t(h[at + 3]) << 24 | std::uint32_t(h[at + 2]) << 16 | std::uint32_t(h[at + 1]) << 8 | h[at];
    }
    /// A UID value of `length` (below 80) bytes at `at`, trailing spaces dropped.
    std::string uid_at(std::uint64_t at, std::uint64_t length) {
        char uid[80] = {};
        in.clear();
        in.seekg(std::streamoff(at));
        in.read(uid, std::streamsize(length));
        std::string text(uid, std::strlen(uid));
        while (!text.empty() && text.back() == ' ') text.pop_back();
        return text;
    }
    /// Whether the value of `length` bytes at `at` starts with `prefix`.
    bool starts_with(std::uint64_t at, std::uint64_t length, const std::string& prefix) {
        char text[16] = {};
        if (length < prefix.size() || prefix.size() > sizeof text) return false;
        in.clear();
        in.seekg(std::streamoff(at));
        return bool(in.read(text, std::streamsize(prefix.size()))) && prefix == std::string(text, prefix.size());
    }
    std::ifstream in;
    unsigned char h[12];
};

/// The overlay planes (even groups 60xx) and curves (even groups 50xx, retired) at the top
/// level of a data set, as GDCM reads them. GDCM asserts on an overlay element it does not
/// know (Overlay Activation Layer, 60xx,1001, among them), on a retired Overlay Compression
/// Code other than "NONE" or Overlay Format other than "RECT", on a plane without Overlay
/// Data (60xx,3000) whose size does not fill whole bytes (its bits would lie in the pixel
/// data's unused ones, retired; read as far as the size claims), and on curves whose groups
/// it counts one way and reads another (it counts overlay planes by their Overlay Data). So
/// only planes with their Overlay Data and known attributes pass, and no curve.
struct OverlayCheck {
    std::map<unsigned, bool> planes;  // group: whether it holds Overlay Data

    static bool is_overlay(unsigned group) { return group >= 0x6000 && group <= 0x60ff && group % 2 == 0; }
    static bool is_curve(unsigned group) { return group >= 0x5000 && group <= 0x50ff && group % 2 == 0; }

    /// False for an element GDCM would assert on.
    bool element(ElementReader& r, unsigned group, unsigned element, std::uint64_t at, std::uint64_t length,
                 bool sequence) {
        static const unsigned known[] = {0x0000, 0x0010, 0x0011, 0x0015, 0x0022, 0x0040, 0x0045, 0x0050, 0x0051, 0x0060,
                                         0x0100, 0x0102, 0x0110, 0x0200, 0x1301, 0x1302, 0x1303, 0x1500, 0x3000};
        if (is_curve(group)) return false;
        if (sequence || std::find(std::begin(known), std::end(known), element) == std::end(known)) return false;
        bool& data = planes[group];
        if (length == 0) return true;  // GDCM passes over empty elements
        if (element == 0x0060) return length == 4 && r.starts_with(at, length, "NONE");
        if (element == 0x0110) return length == 4 && r.starts_with(at, length, "RECT");
        if (element == 0x3000) data = true;
        return true;
    }
    /// False when a plane has no Overlay Data.
    bool complete() const {
        return std::all_of(planes.begin(), planes.end(), [](const auto& g) { return g.second; });
    }
};

/// The header size and value length of the explicit-VR element at p (its first 8 bytes
/// in r.h): complete, or bad_vr for a VR DICOM does not define, or truncated.
Walk explicit_length(ElementReader& r, std::uint64_t p, std::uint64_t size, bool big, std::uint64_t& header,
                     std::uint64_t& length) {
    const std::string vr(reinterpret_cast<const char*>(r.h + 4), 2);
    static const char* long_vrs[] = {"OB", "OW", "OF", "SQ", "UT", "UN", "UC", "UR", "OD", "OL", "OV", "SV", "UV"};
    static const char* short_vrs[] = {"AE", "AS", "AT", "CS", "DA", "DS", "DT", "FL", "FD", "IS", "LO", "LT",
                                      "PN", "SH", "SL", "SS", "ST", "TM", "UI", "UL", "US"};
    auto is = [&](const char* v) { return vr == v; };
    if (std::none_of(std::begin(short_vrs), std::end(short_vrs), is) &&
        std::none_of(std::begin(long_vrs), std::end(long_vrs), is))
        return Walk::bad_vr;
    if (std::any_of(std::begin(long_vrs), std::end(long_vrs), is)) {
        if (size - p < 12 || !r.read_at(p, 12)) return Walk::truncated;
        length = r.u32(8, big);
        header = 12;
    } else {
        length = r.u16(6, big);
    }
    return Walk::complete;
}

/// A walk over the element headers of a DICOM Part 10 file (tag, VR, length; nested items
/// and undefined lengths followed to their delimiters): complete when every data element
/// lies within the file and every explicit VR is one DICOM defines. GDCM asserts (aborts)
/// on cut files, on unknown VRs and on data sets without the "DICM" preamble that are not
/// what it guesses, and reads other cut files short without failing, so only files this
/// walk accepts reach it. Deflated data sets are left to GDCM. GDCM reads a data set with a
/// Recognition Code (0008,0010) as a mixture of ACR-NEMA and DICOM and asserts unless the
/// code is a value that starts "ACR-NEMA", "ACRNEMA" or "MIPS 2.0". The file meta information
/// (group 0002, explicit VR, no sequences) must come first and name the transfer syntax:
/// GDCM guesses the encoding of a file without it, and a wrong guess reads values as
/// lengths (a 900-byte file made its scanner allocate 0.8 GB) or asserts.
Walk walk_elements(const std::string& file, Layout& layout) {
    ElementReader r(file);
    r.in.seekg(0, std::ios::end);
    const std::uint64_t size = std::uint64_t(r.in.tellg());
    layout = Layout{Layout::unknown, size};
    if (size < 132 || !r.read_at(128, 4) || std::memcmp(r.h, "DICM", 4) != 0) return Walk::no_preamble;
    std::uint64_t p = 132;
    std::string syntax;
    OverlayCheck overlays;
    int depth = 0;  // open undefined-length sequences and items
    bool data_set = false;
    while (p < size) {
        if (size - p < 8 || !r.read_at(p, 8)) return Walk::truncated;
        const bool meta = r.u16(0, false) == 0x0002;
        if ((meta && data_set && depth <= 0) || (!meta && p == 132)) return Walk::bad_meta;  // not first
        if (!meta && !data_set && syntax.empty()) return Walk::bad_meta;  // no transfer syntax
        data_set = data_set || !meta;
        const bool implicit = !meta && syntax == "1.2.840.10008.1.2";
        const bool big = !meta && syntax == "1.2.840.10008.1.2.2";
        if (!meta && syntax == "1.2.840.10008.1.2.1.99") {  // deflated: GDCM's to judge
            layout.kind = Layout::deflated;
            return Walk::complete;
        }
        const unsigned group = r.u16(0, big), element = r.u16(2, big);
        std::uint64_t header = 8, length = 0;
        if (group == 0xfffe || implicit) {
            length = r.u32(4, big);
        } else if (const Walk w = explicit_length(r, p, size, big, header, length); w != Walk::complete) {
            return w;
        }
        if (meta && (length == 0xffffffffu || (r.h[4] == 'S' && r.h[5] == 'Q'))) return Walk::bad_meta;
        if (group == 0xfffe && (element == 0xe00d || element == 0xe0dd)) {
            --depth;  // a delimiter closes an undefined length
            p += header;
            continue;
        }
        const bool cut = length != 0xffffffffu && size - p - header < length;  // told as truncated below
        if (!meta && depth == 0 && group == 0x0008 && element == 0x0010 && length != 0 && !cut) {
            const bool sequence = length == 0xffffffffu || (header == 12 && r.h[4] == 'S' && r.h[5] == 'Q');
            const std::uint64_t at = p + header;
            if (sequence || !(r.starts_with(at, length, "ACR-NEMA") || r.starts_with(at, length, "ACRNEMA") ||
                              r.starts_with(at, length, "MIPS 2.0")))
                return Walk::bad_recognition;
        }
        if (!meta && depth == 0 && (OverlayCheck::is_overlay(group) || OverlayCheck::is_curve(group)) && !cut &&
            !overlays.element(r, group, element, p + header, length,
                              length == 0xffffffffu || (header == 12 && r.h[4] == 'S' && r.h[5] == 'Q')))
            return Walk::bad_overlay;
        const bool pixels = group == 0x7fe0 && element == 0x0010 && depth == 0;
        if (pixels) layout = length == 0xffffffffu ? Layout{Layout::encapsulated, size - p} : Layout{Layout::native, length};
        if (length == 0xffffffffu) {  // the content follows as elements or items up to a delimiter
            ++depth;
            p += header;
            continue;
        }
        if (cut) return Walk::truncated;
        if (meta && element == 0x0000 && length == 4) {  // the group length: the data set follows it
            if (!r.read_at(p + header, 4)) return Walk::truncated;
            const std::uint64_t data_set = p + header + 4 + r.u32(0, false);
            if (data_set + 8 > size) return Walk::truncated;
        }
        if (meta && element == 0x0010 && length < 80)  // the transfer syntax of the data set
            syntax = r.uid_at(p + header, length);
        p += header + length;  // a defined-length value (an item too) lies within the file: skip it
    }
    if (!(data_set && depth <= 0)) return Walk::truncated;
    return overlays.complete() ? Walk::complete : Walk::bad_overlay;
}

void scan(Scan& s, const std::string& path) {
    quiet_gdcm();
    std::error_code ec;
    const bool is_dir = fs::is_directory(path, ec);
    s.dir = is_dir ? path : fs::path(path).parent_path().string();
    if (s.dir.empty()) s.dir = ".";
    if (!is_dir) s.selected = path;
    gdcm::Directory d;
    d.Load(s.dir, false);
    std::vector<std::string> files;
    for (const std::string& f : d.GetFilenames()) {
        if (!fs::is_regular_file(f, ec)) continue;  // FIFOs, devices and sockets are not read
        switch (walk_elements(f, s.layouts[f])) {
        case Walk::complete: files.push_back(f); break;
        case Walk::truncated: throw InputError(f + ": truncated DICOM file (a data element runs past its end)");
        case Walk::bad_vr: throw InputError(f + ": malformed DICOM file (an element with an unknown VR)");
        case Walk::bad_meta:
            throw InputError(f + ": malformed DICOM file (the file meta information, group 0002 with the transfer "
                                 "syntax, must come first and hold no sequences)");
        case Walk::bad_recognition:
            throw InputError(f + ": unsupported DICOM file (a Recognition Code (0008,0010) that is not ACR-NEMA's)");
        case Walk::bad_overlay:
            throw InputError(f + ": unsupported DICOM file (a curve, group 50xx, or an overlay plane, group 60xx, "
                                 "without its Overlay Data or with attributes GDCM does not read)");
        case Walk::no_preamble:
            // README, LICENSE, DIRFILE, ...: not DICOM, not ours. A .dcm that is not DICOM is.
            if (dicom_extension(f))
                throw InputError(f + ": not a readable DICOM file (no DICOM Part 10 \"DICM\" preamble)");
            break;
        }
    }
    if (!is_dir) {
        // Match the given file however it was spelled.
        for (const std::string& f : files)
            if (fs::equivalent(f, path, ec)) s.selected = f;
    }
    for (const gdcm::Tag& t : {tag_series_uid, tag_position, tag_orientation, tag_pixel_spacing, tag_rows, tag_columns,
                               tag_slope, tag_intercept, tag_description, tag_frames, tag_thickness, tag_bits,
                               tag_samples, tag_bits_stored, tag_high_bit, tag_photometric})
        s.scanner.AddTag(t);
    if (!s.scanner.Scan(files)) throw InputError(s.dir + ": cannot scan the DICOM files");
    std::sort(files.begin(), files.end(), natural_less);
    for (const std::string& f : files) {
        if (!s.scanner.IsKey(f.c_str())) {
            // README, LICENSE, DIRFILE, ...: not DICOM, not ours. A .dcm that is not DICOM is.
            if (dicom_extension(f)) throw InputError(f + ": not a readable DICOM file");
            continue;
        }
        const std::string uid = trimmed(s.scanner.GetValue(f.c_str(), tag_series_uid));
        if (uid.empty()) throw InputError(f + ": DICOM file without a SeriesInstanceUID");
        Series& se = s.series[uid];
        se.uid = uid;
        se.files.push_back(f);
        if (se.description.empty()) se.description = trimmed(s.scanner.GetValue(f.c_str(), tag_description));
        const std::vector<double> rows = numbers(s.scanner.GetValue(f.c_str(), tag_rows));
        const std::vector<double> cols = numbers(s.scanner.GetValue(f.c_str(), tag_columns));
        se.rows = rows.empty() || !(rows[0] >= 0 && rows[0] <= 65535) ? 0 : std::size_t(rows[0]);
        se.columns = cols.empty() || !(cols[0] >= 0 && cols[0] <= 65535) ? 0 : std::size_t(cols[0]);
    }
    if (s.series.empty()) throw InputError(s.dir + ": no DICOM files in the directory");
}

const Series& choose(const Scan& s, const std::string& uid) {
    if (!uid.empty()) {
        const auto it = s.series.find(uid);
        if (it == s.series.end()) {
            std::string known;
            for (const auto& [u, se] : s.series) known += (known.empty() ? "" : ", ") + u;
            throw InputError(s.dir + ": no DICOM series with UID " + uid + " (found: " + known + ")");
        }
        return it->second;
    }
    if (!s.selected.empty() && s.scanner.IsKey(s.selected.c_str()))
        return s.series.at(trimmed(s.scanner.GetValue(s.selected.c_str(), tag_series_uid)));
    // The largest series; a tie is for the user to settle.
    const Series* best = nullptr;
    bool tie = false;
    for (const auto& [u, se] : s.series) {
        if (!best || se.files.size() > best->files.size()) {
            best = &se;
            tie = false;
        } else if (se.files.size() == best->files.size()) {
            tie = true;
        }
    }
    if (tie)
        throw InputError(s.dir + ": " + std::to_string(s.series.size()) + " DICOM series of " +
                         std::to_string(best->files.size()) +
                         " files each; choose one with --series UID (clfractal info lists them)");
    return *best;
}

StoredKind stored_kind_of(const gdcm::PixelFormat& pf, const std::string& file) {
    if (pf.GetSamplesPerPixel() != 1)
        throw InputError(file + ": " + std::to_string(pf.GetSamplesPerPixel()) +
                         " samples per pixel; only greyscale DICOM is supported");
    switch (pf.GetScalarType()) {
    case gdcm::PixelFormat::UINT8: return StoredKind::uint8;
    case gdcm::PixelFormat::INT8: return StoredKind::int8;
    case gdcm::PixelFormat::UINT16: return StoredKind::uint16;
    case gdcm::PixelFormat::INT16: return StoredKind::int16;
    case gdcm::PixelFormat::UINT32: return StoredKind::uint32;
    case gdcm::PixelFormat::INT32: return StoredKind::int32;
    case gdcm::PixelFormat::FLOAT32: return StoredKind::float32;
    case gdcm::PixelFormat::FLOAT64: return StoredKind::float64;
    default:
        throw InputError(file + ": DICOM pixel format " + pf.GetScalarTypeAsString() + " is not supported");
    }
}

/// A series opened for reading: sorted slices, geometry, the stored kind.
class DicomSource : public SliceSource {
public:
    /// `in_core`: the caller keeps every slice's stored values (read_dicom) and settles the
    /// type itself; otherwise a first pass finds the range where the type depends on it.
    DicomSource(const std::string& path, const std::string& uid, bool in_core = false) : path_(path) {
        Scan s;
        scan(s, path);
        const Series& se = choose(s, uid);
        const gdcm::Scanner& sc = s.scanner;
        const std::string& first = se.files.front();
        if (se.files.size() == 1 && !numbers(sc.GetValue(first.c_str(), tag_frames)).empty() &&
            numbers(sc.GetValue(first.c_str(), tag_frames))[0] > 1)
            throw InputError(first + ": multi-frame DICOM files are not supported (one slice per file)");
        const std::vector<double> iop = numbers(sc.GetValue(first.c_str(), tag_orientation));
        if (iop.size() != 6 && se.files.size() > 1)
            throw InputError(first + ": no ImageOrientationPatient; the slices cannot be ordered (truncated, or not an image)");
        const Frame frame = slice_frame(iop);
        read_slices(sc, se, iop, frame[2]);
        std::stable_sort(slices_.begin(), slices_.end(),
                         [](const Slice& a, const Slice& b) { return a.position < b.position; });
        check_spacing(s.dir);
        read_geometry(sc, first, iop, frame);
        check_dims(dims, s.dir);
        dir_ = s.dir;
        for (const Slice& sl : slices_) check_pixel_data(s, sl.file);

        // The stored kind from the first slice; every slice is checked against it.
        decode(0);
        kind_ = slice_kind_;
        for (const Slice& sl : slices_) maps_.push_back(sl.map);
        if (in_core) return;
        settle_type_from_slices();
    }

    /// The value type, from the range [lo, hi] of every stored value.
    void settle_type(double lo, double hi) { type = rescale_type(kind_, maps_, lo, hi, slices_.front().file); }

    void read_slice(std::size_t z, void* dst) override {
        decode(z);
        rescale_values(buffer_.data(), kind_, slice_values(), slices_[z].map, dst, type);
    }

    /// Slice z's stored values (nx*ny of stored_kind()).
    const std::vector<unsigned char>& stored_slice(std::size_t z) {
        decode(z);
        return buffer_;
    }
    StoredKind stored_kind() const { return kind_; }
    const Rescale& map(std::size_t z) const { return slices_[z].map; }

    std::vector<std::string> notes() const;

private:
    using Frame = std::array<std::array<double, 3>, 3>;  ///< row, column and normal directions

    std::size_t slice_values() const { return dims.nx * dims.ny; }

    /// The row, column and normal directions from ImageOrientationPatient (identity without it).
    static Frame slice_frame(const std::vector<double>& iop) {
        std::array<double, 3> row{1, 0, 0}, col{0, 1, 0}, normal{0, 0, 1};
        if (iop.size() == 6) {
            row = {iop[0], iop[1], iop[2]};
            col = {iop[3], iop[4], iop[5]};
            normal = {row[1] * col[2] - row[2] * col[1], row[2] * col[0] - row[0] * col[2],
                      row[0] * col[1] - row[1] * col[0]};
        }
        return {row, col, normal};
    }

    /// One Slice per file of the series (unsorted), each checked against the first's size
    /// and orientation.
    void read_slices(const gdcm::Scanner& sc, const Series& se, const std::vector<double>& iop,
                     const std::array<double, 3>& normal) {
        const std::string& first = se.files.front();
        for (const std::string& f : se.files) {
            const char* name = f.c_str();
            if (numbers(sc.GetValue(name, tag_rows)) != numbers(sc.GetValue(first.c_str(), tag_rows)) ||
                numbers(sc.GetValue(name, tag_columns)) != numbers(sc.GetValue(first.c_str(), tag_columns)))
                throw InputError(f + ": slice is " + trimmed(sc.GetValue(name, tag_columns)) + "x" +
                                 trimmed(sc.GetValue(name, tag_rows)) + ", but " + name_of(first) + " is " +
                                 trimmed(sc.GetValue(first.c_str(), tag_columns)) + "x" +
                                 trimmed(sc.GetValue(first.c_str(), tag_rows)) + "; one series must not mix sizes");
            const std::vector<double> o = numbers(sc.GetValue(name, tag_orientation));
            for (std::size_t i = 0; i < o.size() && i < iop.size(); ++i)
                if (o.size() != iop.size() || std::fabs(o[i] - iop[i]) > 1e-4)
                    throw InputError(f + ": ImageOrientationPatient differs from " + name_of(first) +
                                     "'s; one series must not mix orientations");
            const std::vector<double> ipp = numbers(sc.GetValue(name, tag_position));
            if (ipp.size() != 3 && se.files.size() > 1)
                throw InputError(f + ": no ImagePositionPatient; the slices cannot be ordered (truncated, or not an image)");
            Slice sl;
            sl.file = f;
            if (ipp.size() == 3) sl.position = ipp[0] * normal[0] + ipp[1] * normal[1] + ipp[2] * normal[2];
            const std::vector<double> slope = numbers(sc.GetValue(name, tag_slope));
            const std::vector<double> intercept = numbers(sc.GetValue(name, tag_intercept));
            if (!slope.empty()) sl.map.slope = slope[0];
            if (!intercept.empty()) sl.map.intercept = intercept[0];
            slices_.push_back(sl);
        }
    }

    /// Spacing, origin, axes and dims from the first file and the sorted slices.
    void read_geometry(const gdcm::Scanner& sc, const std::string& first, const std::vector<double>& iop,
                       const Frame& frame) {
        const std::vector<double> ps = numbers(sc.GetValue(first.c_str(), tag_pixel_spacing));
        if (ps.size() == 2 && ps[0] > 0 && ps[1] > 0) spacing = {ps[1], ps[0], 1.0};  // row spacing is y
        if (slices_.size() > 1) {
            spacing[2] = (slices_.back().position - slices_.front().position) / double(slices_.size() - 1);
        } else {
            const std::vector<double> t = numbers(sc.GetValue(first.c_str(), tag_thickness));
            if (!t.empty() && t[0] > 0) spacing[2] = t[0];
        }
        const std::vector<double> ipp0 = numbers(sc.GetValue(slices_.front().file.c_str(), tag_position));
        if (ipp0.size() == 3 && iop.size() == 6) {
            oriented = true;
            std::copy(ipp0.begin(), ipp0.end(), this->origin.begin());
            axes = frame;
        }
        const std::vector<double> rows = numbers(sc.GetValue(first.c_str(), tag_rows));
        const std::vector<double> cols = numbers(sc.GetValue(first.c_str(), tag_columns));
        if (rows.empty() || cols.empty() || !(rows[0] >= 1 && rows[0] <= 65535) || !(cols[0] >= 1 && cols[0] <= 65535))
            throw InputError(first + ": no Rows/Columns (1 to 65535): not an image");
        dims = Dims{std::size_t(cols[0]), std::size_t(rows[0]), slices_.size()};
    }

    /// The value type, after a pass over the stored values where the type depends on their range.
    void settle_type_from_slices() {
        const bool integer_data = kind_ != StoredKind::float32 && kind_ != StoredKind::float64;
        const bool integral = std::all_of(maps_.begin(), maps_.end(), [](const Rescale& m) { return m.integral(); });
        const bool shifts = std::any_of(maps_.begin(), maps_.end(), [](const Rescale& m) { return m.intercept != 0; });
        double lo = 0, hi = 0;
        if (integer_data && integral && shifts) {
            // The type depends on the range of the results: one pass over the stored values.
            lo = INFINITY;
            hi = -INFINITY;
            for (std::size_t z = 0; z < slices_.size(); ++z) {
                if (z > 0) decode(z);
                stored_range(buffer_.data(), kind_, slice_values(), lo, hi);
            }
        }
        settle_type(lo, hi);
    }

    /// Before GDCM decodes (and allocates) a slice: the pixel data its header claims
    /// (Rows x Columns x BitsAllocated) is there (native), or can come from the bytes that
    /// hold it (encapsulated or deflated: at most the codec's expansion).
    void check_pixel_data(const Scan& s, const std::string& f) const {
        const std::vector<double> bits = numbers(s.scanner.GetValue(f.c_str(), tag_bits));
        const double b = bits.empty() ? 16 : bits[0];
        if (!(b >= 1 && b <= 64)) throw InputError(f + ": BitsAllocated " + std::to_string(b) + " is not 1 to 64");
        // GDCM asserts (aborts) on SamplesPerPixel above 4, BitsStored above BitsAllocated
        // and HighBit not below BitsStored.
        const std::vector<double> samples = numbers(s.scanner.GetValue(f.c_str(), tag_samples));
        if (!samples.empty() && samples[0] != 1)
            throw InputError(f + ": " + std::to_string(std::lround(std::min(samples[0], 1e9))) +
                             " samples per pixel; only greyscale DICOM is supported");
        // GDCM asserts on a palette image without its lookup tables: greyscale only.
        const std::string photometric = trimmed(s.scanner.GetValue(f.c_str(), tag_photometric));
        if (!photometric.empty() && photometric != "MONOCHROME1" && photometric != "MONOCHROME2")
            throw InputError(f + ": PhotometricInterpretation " + quote_input(photometric) +
                             "; only greyscale (MONOCHROME1, MONOCHROME2) DICOM is supported");
        const std::vector<double> stored = numbers(s.scanner.GetValue(f.c_str(), tag_bits_stored));
        const std::vector<double> high = numbers(s.scanner.GetValue(f.c_str(), tag_high_bit));
        const double bs = stored.empty() ? b : stored[0];
        if (!(bs >= 1 && bs <= b) || (!high.empty() && !(high[0] >= 0 && high[0] < bs)))
            throw InputError(f + ": BitsStored/HighBit do not fit BitsAllocated " + std::to_string(std::lround(b)));
        const std::uint64_t claimed = std::uint64_t(slice_values()) * ((std::uint64_t(b) + 7) / 8);
        const auto it = s.layouts.find(f);
        const Layout l = it == s.layouts.end() ? Layout{} : it->second;
        const std::string layout = "the pixel data (" + std::to_string(dims.nx) + "x" + std::to_string(dims.ny) + ", " +
                                   std::to_string(std::uint64_t(b)) + " bits allocated)";
        const std::uint64_t ratio = l.kind == Layout::native || l.kind == Layout::unknown ? 1
                                    : l.kind == Layout::deflated                         ? ExpansionLimits::deflate
                                                                                         : ExpansionLimits::other;
        check_claim(f, l.kind == Layout::native ? "the pixel data element" : "the file", layout, claimed, l.pixel_bytes, ratio);
    }

    void check_spacing(const std::string& dir) {
        for (std::size_t i = 1; i < slices_.size(); ++i)
            if (std::fabs(slices_[i].position - slices_[i - 1].position) < 1e-6)
                throw InputError(slices_[i].file + ": same slice position as " + name_of(slices_[i - 1].file) +
                                 " (" + std::to_string(slices_[i].position) + "); duplicate slices in one series");
        if (slices_.size() < 3) return;
        std::vector<double> gaps;
        for (std::size_t i = 1; i < slices_.size(); ++i) gaps.push_back(slices_[i].position - slices_[i - 1].position);
        std::vector<double> sorted = gaps;
        std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
        const double usual = sorted[sorted.size() / 2];
        for (std::size_t i = 0; i < gaps.size(); ++i) {
            if (std::fabs(gaps[i] - usual) <= 0.01 * usual) continue;
            std::ostringstream m;
            m.precision(6);
            m << dir << ": uneven slice spacing: " << gaps[i] << " between " << name_of(slices_[i].file) << " (at "
              << slices_[i].position << ") and " << name_of(slices_[i + 1].file) << " (at " << slices_[i + 1].position
              << "), " << usual << " elsewhere";
            if (gaps[i] > 1.5 * usual)
                m << " (" << std::lround(gaps[i] / usual) - 1 << " slice(s) missing)";
            throw InputError(m.str());
        }
    }

    /// Decodes slice z's stored values into buffer_ (and slice_kind_).
    void decode(std::size_t z) {
        const std::string& f = slices_[z].file;
        gdcm::ImageReader r;
        r.SetFileName(f.c_str());
        // GDCM reads a cut file without failing; it only warns: listen for that warning.
        static std::ostringstream warnings;
        warnings.str("");
        gdcm::Trace::SetWarningStream(warnings);
        gdcm::Trace::SetWarning(true);
        const bool read = r.Read();
        gdcm::Trace::SetWarning(false);
        if (warnings.str().find("Incomplete Pixel Data") != std::string::npos)
            throw InputError(f + ": truncated: incomplete pixel data");
        if (!read)
            throw InputError(f + ": GDCM cannot read an image from it (truncated, no pixel data, or a "
                                 "transfer syntax it cannot decode)");
        const gdcm::Image& img = r.GetImage();
        if (img.GetDimension(0) != dims.nx || img.GetDimension(1) != dims.ny ||
            (img.GetNumberOfDimensions() > 2 && img.GetDimension(2) > 1))
            throw InputError(f + ": image is not " + std::to_string(dims.nx) + "x" + std::to_string(dims.ny) +
                             " with one frame");
        slice_kind_ = stored_kind_of(img.GetPixelFormat(), f);
        if (z > 0 && slice_kind_ != kind_)
            throw InputError(f + ": stored type " + stored_kind_name(slice_kind_) + " differs from the series' " +
                             stored_kind_name(kind_));
        const std::size_t bytes = slice_values() * stored_kind_size(slice_kind_);
        if (img.GetBufferLength() != bytes)
            throw InputError(f + ": pixel data holds " + std::to_string(img.GetBufferLength()) + " bytes, expected " +
                             std::to_string(bytes));
        buffer_.resize(bytes);
        if (!img.GetBuffer(reinterpret_cast<char*>(buffer_.data())))
            throw InputError(f + ": GDCM cannot decode the pixel data");
    }

    std::string path_, dir_;
    std::vector<Slice> slices_;
    std::vector<Rescale> maps_;
    StoredKind kind_ = StoredKind::uint8, slice_kind_ = StoredKind::uint8;
    std::vector<unsigned char> buffer_;
};

std::unique_ptr<SliceSource> open_series_slices(const std::string& path, const std::string& series_uid) {
    return std::make_unique<DicomSource>(path, series_uid);
}

Volume read_series(const std::string& path, const std::string& series_uid) {
    // Every slice decoded once: stored values kept until the range settles the type.
    DicomSource s(path, series_uid, true);
    const std::size_t plane = s.dims.nx * s.dims.ny, bytes = plane * stored_kind_size(s.stored_kind());
    std::vector<unsigned char> stored(bytes * s.dims.nz);
    double lo = INFINITY, hi = -INFINITY;
    for (std::size_t z = 0; z < s.dims.nz; ++z) {
        std::memcpy(&stored[z * bytes], s.stored_slice(z).data(), bytes);
        stored_range(&stored[z * bytes], s.stored_kind(), plane, lo, hi);
    }
    s.settle_type(lo, hi);
    Volume v(s.dims, s.type, path);
    const std::size_t out_bytes = plane * value_size(s.type);
    for (std::size_t z = 0; z < s.dims.nz; ++z)
        rescale_values(&stored[z * bytes], s.stored_kind(), plane, s.map(z), static_cast<unsigned char*>(v.data()) + z * out_bytes,
                       s.type);
    v.spacing = s.spacing;
    v.oriented = s.oriented;
    v.origin = s.origin;
    v.axes = s.axes;
    return v;
}

std::vector<std::string> series_notes(const std::string& path, const std::string& series_uid) {
    Scan s;
    scan(s, path);
    const Series* chosen = nullptr;
    try {
        chosen = &choose(s, series_uid);
    } catch (const InputError&) {
        // A tie: list them all, none chosen.
    }
    std::vector<std::string> lines;
    lines.push_back(std::to_string(s.series.size()) + " DICOM series in " + s.dir + ":");
    for (const auto& [uid, se] : s.series)
        lines.push_back((chosen == &se ? "* " : "  ") + uid + "  " + std::to_string(se.files.size()) + " files  " +
                        std::to_string(se.columns) + "x" + std::to_string(se.rows) +
                        (se.description.empty() ? "" : "  \"" + se.description + "\""));
    lines.push_back("(* = read; choose another with --series UID)");
    return lines;
}

const DicomModule module{dicom_module_abi, read_series, open_series_slices, series_notes};

}  // namespace
}  // namespace clfractal::io

extern "C" __attribute__((visibility("default"))) const clfractal::io::DicomModule* clfractal_dicom_module() {
    return &clfractal::io::module;
}
