// TIFF through libtiff: one multi-page file (page = z) or a directory of single-page slices
// in natural file-name order; one sample per pixel; strips or tiles, any compression
// libtiff decodes. Read one page at a time, so a stack streams slice by slice.
#include "io/formats.hpp"

#include <tiffio.h>

#include <algorithm>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <mutex>

#include "io/input_guard.hpp"

namespace fs = std::filesystem;

namespace clfractal::io {
namespace {

// libtiff reports through global handlers: keep the last message for our one-line error.
thread_local std::string tiff_message;
void tiff_error(const char* module, const char* fmt, va_list ap) {
    char buf[512];
    std::vsnprintf(buf, sizeof buf, fmt, ap);
    tiff_message = std::string(module ? module : "") + (module ? ": " : "") + buf;
}
void tiff_warning(const char*, const char*, va_list) {}
void install_handlers() {
    static std::once_flag once;
    std::call_once(once, [] {
        TIFFSetErrorHandler(tiff_error);
        TIFFSetWarningHandler(tiff_warning);
    });
}

struct TiffClose {
    void operator()(TIFF* t) const { TIFFClose(t); }
};
using TiffPtr = std::unique_ptr<TIFF, TiffClose>;

TiffPtr open_tiff(const std::string& file) {
    regular_file_size(file, file);
    install_handlers();
    tiff_message.clear();
    TiffPtr t(TIFFOpen(file.c_str(), "r"));
    if (!t) throw InputError(file + ": cannot read TIFF" + (tiff_message.empty() ? "" : ": " + tiff_message));
    return t;
}

/// The layout of one page.
struct Page {
    std::uint32_t width = 0, height = 0;
    StoredKind kind = StoredKind::uint8;
    bool operator==(const Page& o) const { return width == o.width && height == o.height && kind == o.kind; }
};

std::string describe(const Page& p) {
    return std::to_string(p.width) + "x" + std::to_string(p.height) + " " + stored_kind_name(p.kind);
}

/// The most `compression` can expand its data (ExpansionLimits).
std::uint64_t expansion(std::uint16_t compression) {
    switch (compression) {
    case COMPRESSION_NONE: return 1;
    case COMPRESSION_LZW: return ExpansionLimits::lzw;
    case COMPRESSION_PACKBITS: return ExpansionLimits::packbits;
    case COMPRESSION_ADOBE_DEFLATE:
    case COMPRESSION_DEFLATE: return ExpansionLimits::deflate;
    case COMPRESSION_JPEG:
    case COMPRESSION_OJPEG: return ExpansionLimits::jpeg;
    default: return ExpansionLimits::other;
    }
}

/// Before a page is allocated or decoded: its strips (or tiles) lie within the file, tiles
/// are no larger than the page (rounded up to libtiff's 16), and the strips hold the page
/// (uncompressed) or can expand to it (compressed: at most expansion(compression):1).
void check_page_data(TIFF* t, const std::string& file, std::size_t page, std::uint64_t claimed, std::uint32_t width,
                     std::uint32_t height) {
    const std::string where = file + ": page " + std::to_string(page);
    const std::uint64_t file_size = regular_file_size(file, file);
    const bool tiled = TIFFIsTiled(t);
    if (tiled) {
        std::uint32_t tw = 0, th = 0;
        TIFFGetField(t, TIFFTAG_TILEWIDTH, &tw);
        TIFFGetField(t, TIFFTAG_TILELENGTH, &th);
        if (tw == 0 || th == 0 || tw > (std::uint64_t(width) + 15) / 16 * 16 || th > (std::uint64_t(height) + 15) / 16 * 16)
            throw InputError(where + ": tiles of " + std::to_string(tw) + "x" + std::to_string(th) + " for a page of " +
                             std::to_string(width) + "x" + std::to_string(height));
    }
    const std::uint64_t pieces = tiled ? std::uint64_t(TIFFNumberOfTiles(t)) : std::uint64_t(TIFFNumberOfStrips(t));
    std::uint64_t* offsets = nullptr;
    std::uint64_t* counts = nullptr;
    if (pieces == 0 || !TIFFGetField(t, tiled ? TIFFTAG_TILEOFFSETS : TIFFTAG_STRIPOFFSETS, &offsets) ||
        !TIFFGetField(t, tiled ? TIFFTAG_TILEBYTECOUNTS : TIFFTAG_STRIPBYTECOUNTS, &counts) || !offsets || !counts)
        throw InputError(where + ": no " + (tiled ? "tile" : "strip") + " offsets or byte counts");
    std::uint64_t stored = 0;
    for (std::uint64_t i = 0; i < pieces; ++i) {
        if (offsets[i] > file_size || counts[i] > file_size - offsets[i])
            throw InputError(where + ": " + (tiled ? "tile " : "strip ") + std::to_string(i) + " (" +
                             std::to_string(counts[i]) + " bytes at " + std::to_string(offsets[i]) +
                             ") lies past the end of the file (" + std::to_string(file_size) + " bytes)");
        stored += counts[i];
    }
    std::uint16_t compression = COMPRESSION_NONE;
    TIFFGetFieldDefaulted(t, TIFFTAG_COMPRESSION, &compression);
    check_claim(where, tiled ? "tiles" : "strips",
                "the page (" + std::to_string(width) + "x" + std::to_string(height) + ", compression " +
                    std::to_string(compression) + ")",
                claimed, stored, expansion(compression));
}

Page page_of(TIFF* t, const std::string& file, std::size_t page) {
    Page p;
    std::uint16_t spp = 1, bps = 1, format = SAMPLEFORMAT_UINT;
    TIFFGetField(t, TIFFTAG_IMAGEWIDTH, &p.width);
    TIFFGetField(t, TIFFTAG_IMAGELENGTH, &p.height);
    TIFFGetFieldDefaulted(t, TIFFTAG_SAMPLESPERPIXEL, &spp);
    TIFFGetFieldDefaulted(t, TIFFTAG_BITSPERSAMPLE, &bps);
    TIFFGetFieldDefaulted(t, TIFFTAG_SAMPLEFORMAT, &format);
    const std::string where = file + ": page " + std::to_string(page);
    if (p.width == 0 || p.height == 0) throw InputError(where + ": no image size");
    check_dims(Dims{p.width, p.height, 1}, where);
    if (spp != 1)
        throw InputError(where + ": " + std::to_string(spp) + " samples per pixel; only greyscale (1 sample) is supported");
    const bool sign = format == SAMPLEFORMAT_INT, flt = format == SAMPLEFORMAT_IEEEFP;
    if (format != SAMPLEFORMAT_UINT && !sign && !flt)
        throw InputError(where + ": sample format " + std::to_string(format) + " is not supported");
    if (flt && bps == 32) p.kind = StoredKind::float32;
    else if (flt && bps == 64) p.kind = StoredKind::float64;
    else if (!flt && bps == 8) p.kind = sign ? StoredKind::int8 : StoredKind::uint8;
    else if (!flt && bps == 16) p.kind = sign ? StoredKind::int16 : StoredKind::uint16;
    else if (!flt && bps == 32) p.kind = sign ? StoredKind::int32 : StoredKind::uint32;
    else throw InputError(where + ": " + std::to_string(bps) + "-bit samples are not supported (8, 16 or 32 bits)");
    check_page_data(t, file, page, std::uint64_t(p.width) * p.height * stored_kind_size(p.kind), p.width, p.height);
    return p;
}

/// Decodes the current page into dst (width*height stored values), strips or tiles.
void read_page(TIFF* t, const Page& p, unsigned char* dst, const std::string& file, std::size_t page) {
    const std::size_t vs = stored_kind_size(p.kind);
    const std::size_t row = std::size_t(p.width) * vs;
    const std::string where = file + ": page " + std::to_string(page);
    tiff_message.clear();
    auto fail = [&](const char* what) {
        throw InputError(where + ": " + what + (tiff_message.empty() ? "" : ": " + tiff_message));
    };
    std::uint16_t planar = PLANARCONFIG_CONTIG;
    TIFFGetFieldDefaulted(t, TIFFTAG_PLANARCONFIG, &planar);
    if (TIFFIsTiled(t)) {
        std::uint32_t tw = 0, th = 0;
        TIFFGetField(t, TIFFTAG_TILEWIDTH, &tw);
        TIFFGetField(t, TIFFTAG_TILELENGTH, &th);
        if (tw == 0 || th == 0) fail("bad tile size");
        std::vector<unsigned char> tile(std::size_t(TIFFTileSize(t)));
        if (tile.size() < std::size_t(tw) * th * vs) fail("bad tile size");
        for (std::uint32_t y = 0; y < p.height; y += th)
            for (std::uint32_t x = 0; x < p.width; x += tw) {
                if (TIFFReadTile(t, tile.data(), x, y, 0, 0) < 0) fail("cannot decode a tile");
                const std::size_t w = std::min(tw, p.width - x), h = std::min(th, p.height - y);
                for (std::size_t r = 0; r < h; ++r)
                    std::memcpy(dst + (y + r) * row + x * vs, tile.data() + r * tw * vs, w * vs);
            }
    } else {
        std::uint32_t rows_per_strip = p.height;
        TIFFGetFieldDefaulted(t, TIFFTAG_ROWSPERSTRIP, &rows_per_strip);
        rows_per_strip = std::min(std::max<std::uint32_t>(rows_per_strip, 1), p.height);
        const tstrip_t strips = TIFFNumberOfStrips(t);
        std::size_t done = 0;
        for (tstrip_t s = 0; s < strips && done < p.height; ++s) {
            const std::size_t rows = std::min<std::size_t>(rows_per_strip, p.height - done);
            const tmsize_t got = TIFFReadEncodedStrip(t, s, dst + done * row, tmsize_t(rows * row));
            if (got < 0) fail("cannot decode a strip");
            if (std::size_t(got) < rows * row) fail("strip truncated");
            done += rows;
        }
        if (done < p.height) fail("fewer strips than rows");
    }
}

bool tiff_extension(const fs::path& p) {
    std::string ext = p.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return ext == ".tif" || ext == ".tiff";
}

/// A multi-page file: page z is slice z; pages are reached with TIFFSetDirectory.
class MultiPageSource : public SliceSource {
public:
    explicit MultiPageSource(const std::string& file) : file_(file), tiff_(open_tiff(file)) {
        std::size_t pages = 0;
        tiff_message.clear();
        do {
            const Page p = page_of(tiff_.get(), file_, pages);
            if (pages == 0) page_ = p;
            else if (!(p == page_))
                throw InputError(file_ + ": page " + std::to_string(pages) + " is " + describe(p) + ", page 0 is " +
                                 describe(page_) + "; every page must match");
            ++pages;
        } while (TIFFReadDirectory(tiff_.get()));
        // The chain of pages ends without a complaint; a broken link is a truncated file.
        if (!tiff_message.empty())
            throw InputError(file_ + ": page " + std::to_string(pages) + " cannot be read (truncated?): " + tiff_message);
        dims = Dims{page_.width, page_.height, pages};
        check_dims(dims, file_);
        type = value_type_for(page_.kind, file_);
        buffer_.resize(std::size_t(page_.width) * page_.height * stored_kind_size(page_.kind));
        current_ = pages - 1;
    }
    void read_slice(std::size_t z, void* dst) override {
        // In z order the next page is one step on; anything else is looked up.
        const bool moved = z == current_ || (z == current_ + 1 ? TIFFReadDirectory(tiff_.get()) == 1
                                                               : TIFFSetDirectory(tiff_.get(), tdir_t(z)) == 1);
        if (!moved) throw InputError(file_ + ": cannot reach page " + std::to_string(z));
        current_ = z;
        read_page(tiff_.get(), page_, buffer_.data(), file_, z);
        convert_values(buffer_.data(), page_.kind, std::size_t(page_.width) * page_.height, dst, type);
    }

private:
    std::string file_;
    TiffPtr tiff_;
    Page page_;
    std::vector<unsigned char> buffer_;
    std::size_t current_ = 0;  // the page the TIFF handle is on
};

/// A directory of single-page files, in natural name order; one file open at a time.
class DirectorySource : public SliceSource {
public:
    explicit DirectorySource(const std::string& dir) {
        std::error_code ec;
        for (const auto& e : fs::directory_iterator(dir, ec))
            if (e.is_regular_file(ec) && tiff_extension(e.path())) files_.push_back(e.path().string());
        if (files_.empty()) throw InputError(dir + ": no .tif/.tiff files in the directory");
        std::sort(files_.begin(), files_.end(), [](const std::string& a, const std::string& b) {
            return natural_less(fs::path(a).filename().string(), fs::path(b).filename().string());
        });
        // Check every slice's header up front: sizes and types must agree.
        for (std::size_t z = 0; z < files_.size(); ++z) {
            TiffPtr t = open_tiff(files_[z]);
            const Page p = page_of(t.get(), files_[z], 0);
            if (TIFFReadDirectory(t.get()))
                throw InputError(files_[z] + ": has several pages; a slice directory needs one page per file");
            if (z == 0) page_ = p;
            else if (!(p == page_))
                throw InputError(files_[z] + ": slice is " + describe(p) + ", but " +
                                 fs::path(files_[0]).filename().string() + " is " + describe(page_) +
                                 "; every slice must match");
        }
        dims = Dims{page_.width, page_.height, files_.size()};
        check_dims(dims, dir);
        type = value_type_for(page_.kind, files_[0]);
        buffer_.resize(std::size_t(page_.width) * page_.height * stored_kind_size(page_.kind));
    }
    void read_slice(std::size_t z, void* dst) override {
        TiffPtr t = open_tiff(files_[z]);
        read_page(t.get(), page_of(t.get(), files_[z], 0), buffer_.data(), files_[z], 0);
        convert_values(buffer_.data(), page_.kind, std::size_t(page_.width) * page_.height, dst, type);
    }

private:
    std::vector<std::string> files_;
    Page page_;
    std::vector<unsigned char> buffer_;
};

}  // namespace

std::unique_ptr<SliceSource> open_tiff_slices(const std::string& path) {
    std::error_code ec;
    if (fs::is_directory(path, ec)) return std::make_unique<DirectorySource>(path);
    return std::make_unique<MultiPageSource>(path);
}

Volume read_tiff(const std::string& path) {
    std::unique_ptr<SliceSource> s = open_tiff_slices(path);
    return read_all_slices(*s, path);
}

}  // namespace clfractal::io
