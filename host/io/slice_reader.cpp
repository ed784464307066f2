// Slice-by-slice readers (docs/definitions.md §28): memory maps for raw data, zlib for gzip data.
#include "clfractal/slice_reader.hpp"

#include "io/output_file.hpp"
#include "clfractal/volume_io.hpp"
#include "io/formats.hpp"
#include "io/nrrd_guard.hpp"

#include <fcntl.h>
#include <omp.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <teem/nrrd.h>

#include "io/nrrd_types.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <vector>

namespace fs = std::filesystem;

namespace clfractal {

namespace {


void swap_bytes(unsigned char* p, std::size_t n, std::size_t size) {
    if (size == 1) return;
    for (std::size_t i = 0; i < n; ++i, p += size) std::reverse(p, p + size);
}


}  // namespace

struct SliceReader::Impl {
    std::string spec;
    Dims dims;
    ValueType type = ValueType::uint8;       // the type read() serves (RawOptions::as, else file_type)
    ValueType file_type = ValueType::uint8;  // the type stored in the file
    std::array<double, 3> spacing{1.0, 1.0, 1.0};
    io::Geometry geometry;  // orientation where the reader knows it
    std::string method = "memory";
    std::size_t file_value_size = 0;  // bytes per value in the file
    bool swap = false;
    std::string data_path;
    std::size_t data_offset = 0;
    std::size_t next = 0;

    int fd = -1;         // mmap
    gzFile gz = nullptr; // gzip
    Volume whole;        // memory
    std::unique_ptr<io::SliceSource> source;  // dicom, tiff
    std::vector<unsigned char> staging;  // file values before conversion (--as)

    std::size_t slice_values() const { return dims.nx * dims.ny; }
    std::size_t slice_bytes() const { return slice_values() * value_size(type); }

    bool peek = false;   // the header only: nothing read whole, no file opened for reading

    Impl(const std::string& s, const RawOptions& raw, bool peek_only = false) : spec(s), peek(peek_only) {
        const std::string synthetic_prefix = "synthetic:";
        if (spec.compare(0, synthetic_prefix.size(), synthetic_prefix) == 0) {
            read_whole(raw);
            return;
        }
        std::error_code ec;
        if (!fs::exists(spec, ec)) throw InputError(spec + ": no such file");
        if (!fs::is_regular_file(spec, ec) && !fs::is_directory(spec, ec))
            throw InputError(spec + ": not a regular file");
        switch (io::detect_format(spec)) {
        case io::Format::nrrd: open_nrrd(raw); break;
        case io::Format::raw: open_raw(raw); break;
        case io::Format::dicom:
        case io::Format::directory_dicom: open_source(io::open_dicom_slices(spec, raw.series), "dicom"); break;
        case io::Format::tiff:
        case io::Format::directory_tiff: open_source(io::open_tiff_slices(spec), "tiff"); break;
        default: read_whole(raw);
        }
        geometry.spacing = spacing;
        if (method == "memory") return;  // read whole (and converted) by read_volume
        type = raw.as.value_or(file_type);
        if (!peek) open();
    }

    ~Impl() { close(); }

    void read_whole(const RawOptions& raw) {
        if (peek) return;  // method stays "memory": the shape is known only once read
        whole = read_volume(spec, raw);
        dims = whole.dims();
        type = whole.type();
        spacing = whole.spacing;
        geometry = io::geometry_of(whole);
        method = "memory";
    }

    void open_source(std::unique_ptr<io::SliceSource> s, const char* name) {
        source = std::move(s);
        dims = source->dims;
        file_type = source->type;
        spacing = source->spacing;
        geometry = io::Geometry{source->spacing, source->oriented, source->origin, source->axes};
        file_value_size = value_size(file_type);
        method = name;
    }

    void open_raw(const RawOptions& raw) {
        std::optional<Dims> d = raw.dims;
        std::optional<ValueType> t = raw.type;
        if (!d || !t) {
            Dims name_dims;
            ValueType name_type;
            if (!parse_raw_name(spec, name_dims, name_type)) return read_whole(raw);  // read_raw's messages
            if (!d) d = name_dims;
            if (!t) t = name_type;
        }
        check_dims(*d, spec);
        dims = *d;
        file_type = *t;
        file_value_size = value_size(file_type);
        const std::uintmax_t expected = dims.vertices() * file_value_size;
        const std::uintmax_t found = fs::file_size(spec);
        if (found != expected)
            throw InputError(spec + (found < expected ? ": truncated" : ": too long") + ": expected " +
                             std::to_string(expected) + " bytes (" + dims_string(dims) + " " + value_type_name(file_type) +
                             "), found " + std::to_string(found));
        swap = raw.big_endian != io::host_big_endian;
        spacing = raw.spacing;
        data_path = spec;
        method = "mmap";
    }

    void open_nrrd(const RawOptions& raw) {
        // The same checked header as read_nrrd: data files, where the data starts.
        const NrrdHeader checked = check_nrrd(spec);
        Nrrd* header = nrrdNew();
        NrrdIoState* nio = nrrdIoStateNew();
        nio->skipData = AIR_TRUE;
        struct Free {
            Nrrd* h;
            NrrdIoState* n;
            ~Free() {
                nrrdNuke(h);
                nrrdIoStateNix(n);
            }
        } free_later{header, nio};
        if (nrrdLoad(header, spec.c_str(), nio)) {
            char* err = biffGetDone(NRRD);
            std::free(err);
            return read_whole(raw);  // read_nrrd words the message
        }
        const bool simple = header->dim == 3 && nio->lineSkip == 0 && nio->byteSkip == 0 && !nio->dataFSkip &&
                            checked.data_files.size() == 1 &&
                            (nio->encoding == nrrdEncodingRaw || nio->encoding == nrrdEncodingGzip) &&
                            value_type_of_nrrd(header->type).has_value();
        if (!simple) return read_whole(raw);
        dims = Dims{header->axis[0].size, header->axis[1].size, header->axis[2].size};
        check_dims(dims, spec);
        file_type = *value_type_of_nrrd(header->type);
        file_value_size = value_size(file_type);
        geometry = io::nrrd_geometry(header);
        spacing = geometry.spacing;
        swap = file_value_size > 1 && (nio->endian == airEndianBig) != io::host_big_endian;
        data_path = checked.data_files[0];
        data_offset = checked.attached ? std::size_t(checked.data_offset) : 0;
        if (nio->encoding == nrrdEncodingGzip) {
            method = "gzip";
        } else {
            method = "mmap";
            const std::uintmax_t expected = dims.vertices() * file_value_size;
            std::error_code ec;
            const std::uintmax_t found = fs::file_size(data_path, ec);
            if (ec) throw InputError(data_path + ": cannot read: " + ec.message());
            if (found < data_offset + expected)
                throw InputError(spec + ": truncated: expected " + std::to_string(expected) + " bytes of data (" +
                                 dims_string(dims) + "), found " + std::to_string(found - std::min(found, std::uintmax_t(data_offset))));
        }
    }

    void open() {
        next = 0;
        if (method == "mmap") {
            fd = ::open(data_path.c_str(), O_RDONLY);
            if (fd < 0) throw InputError(data_path + ": cannot open: " + std::strerror(errno));
        } else if (method == "gzip") {
            const int f = ::open(data_path.c_str(), O_RDONLY);
            if (f < 0) throw InputError(data_path + ": cannot open: " + std::strerror(errno));
            if (::lseek(f, off_t(data_offset), SEEK_SET) < 0) {
                ::close(f);
                throw InputError(data_path + ": cannot seek to the data");
            }
            gz = gzdopen(f, "rb");
            if (!gz) {
                ::close(f);
                throw InputError(data_path + ": cannot open the gzip stream");
            }
            gzbuffer(gz, 1 << 20);
        }
    }

    void close() {
        if (fd >= 0) ::close(fd);
        fd = -1;
        if (gz) gzclose(gz);
        gz = nullptr;
    }

    // Copies `bytes` from the file's mapping: from 8 MiB on, a part a core (each faulting in
    // its own pages of the mapping), else on the calling thread.
    static void copy_on_every_core(unsigned char* dst, const unsigned char* src, std::size_t bytes) {
        const int parts = bytes >= (std::size_t(8) << 20) ? omp_get_max_threads() : 1;
#pragma omp parallel for num_threads(parts) schedule(static, 1) if (parts > 1)
        for (int t = 0; t < parts; ++t) {
            const std::size_t a = bytes * std::size_t(t) / std::size_t(parts), b = bytes * std::size_t(t + 1) / std::size_t(parts);
            std::memcpy(dst + a, src + a, b - a);
        }
    }

    // Reads `bytes` file bytes of the slices [next, next + count) into `dst`.
    void read_file_bytes(unsigned char* dst, std::size_t count) {
        const std::size_t bytes = count * slice_values() * file_value_size;
        if (method == "mmap") {
            // Map just these slices and drop the mapping: resident memory stays one window.
            const std::size_t offset = data_offset + next * slice_values() * file_value_size;
            const std::size_t page = std::size_t(sysconf(_SC_PAGESIZE));
            const std::size_t start = offset / page * page;
            const std::size_t length = offset + bytes - start;
            void* map = ::mmap(nullptr, length, PROT_READ, MAP_PRIVATE, fd, off_t(start));
            if (map == MAP_FAILED) throw InputError(data_path + ": cannot map: " + std::strerror(errno));
            ::madvise(map, length, MADV_SEQUENTIAL);
            copy_on_every_core(dst, static_cast<unsigned char*>(map) + (offset - start), bytes);
            ::munmap(map, length);
        } else {
            std::size_t done = 0;
            while (done < bytes) {
                const unsigned chunk = unsigned(std::min<std::size_t>(bytes - done, 1u << 30));
                const int got = gzread(gz, dst + done, chunk);
                if (got <= 0) {
                    int code = Z_OK;
                    const char* msg = gzerror(gz, &code);
                    throw InputError(spec + ": gzip data " +
                                     (got == 0 ? std::string("truncated") : "corrupt: " + std::string(msg)) +
                                     " at slice " + std::to_string(next + done / (slice_values() * file_value_size)));
                }
                done += std::size_t(got);
                // zlib passes data without a gzip header through unchanged: not ours.
                if (gzdirect(gz)) throw InputError(spec + ": the data is not gzip-compressed");
            }
        }
    }

    void read(void* dst, std::size_t count) {
        if (next + count > dims.nz) throw std::logic_error("SliceReader::read past the last slice");
        if (count == 0) return;
        auto* out = static_cast<unsigned char*>(dst);
        if (method == "memory") {
            std::memcpy(out, static_cast<const unsigned char*>(whole.data()) + next * slice_bytes(),
                        count * slice_bytes());
        } else {
            const bool convert = file_type != type;
            if (convert) staging.resize(count * slice_values() * file_value_size);
            unsigned char* file_values = convert ? staging.data() : out;
            if (source) {
                for (std::size_t i = 0; i < count; ++i)
                    source->read_slice(next + i, file_values + i * slice_values() * file_value_size);
            } else {
                read_file_bytes(file_values, count);
                if (swap) swap_bytes(file_values, count * slice_values(), file_value_size);
            }
            check_finite(file_values, file_type, count * slice_values(), dims, next * slice_values(), spec);
            if (convert) convert_values(file_values, file_type, out, type, count * slice_values());
        }
        next += count;
    }

    void rewind() {
        close();
        open();
    }

    void seek(std::size_t z) {
        if (z > dims.nz) throw std::logic_error("SliceReader::seek past the last slice");
        if (method != "gzip") {
            next = z;
            return;
        }
        // A gzip stream only goes forward: decompress and drop the slices before z.
        if (z < next) rewind();
        std::vector<unsigned char> scratch(slice_values() * file_value_size);
        while (next < z) {
            read_file_bytes(scratch.data(), 1);
            ++next;
        }
    }
};

SliceReader::SliceReader(const std::string& spec, const RawOptions& raw) : impl_(std::make_unique<Impl>(spec, raw)) {}

std::optional<VolumeShape> peek_volume(const std::string& spec, const RawOptions& raw) {
    const SliceReader::Impl header(spec, raw, true);
    if (header.method == "memory") return {};
    return VolumeShape{header.dims, header.type, header.method};
}
SliceReader::~SliceReader() = default;
const Dims& SliceReader::dims() const { return impl_->dims; }
ValueType SliceReader::type() const { return impl_->type; }
const std::array<double, 3>& SliceReader::spacing() const { return impl_->spacing; }
std::size_t SliceReader::slice_bytes() const { return impl_->slice_bytes(); }
const char* SliceReader::method() const { return impl_->method.c_str(); }
void SliceReader::read(void* dst, std::size_t count) { impl_->read(dst, count); }
std::size_t SliceReader::next_slice() const { return impl_->next; }
void SliceReader::rewind() { impl_->rewind(); }
void SliceReader::seek(std::size_t z) { impl_->seek(z); }

struct NrrdSliceWriter::Impl {
    std::unique_ptr<io::NrrdWriter> out;
    std::size_t slice_bytes = 0, nz = 0, written = 0;
};

NrrdSliceWriter::NrrdSliceWriter(const std::string& path, const Dims& dims, ValueType type,
                                 const std::array<double, 3>& spacing)
    : impl_(std::make_unique<Impl>()) {
    io::Geometry g;
    g.spacing = spacing;
    impl_->out = std::make_unique<io::NrrdWriter>(path, dims, type, g);
    impl_->slice_bytes = dims.nx * dims.ny * value_size(type);
    impl_->nz = dims.nz;
}

NrrdSliceWriter::~NrrdSliceWriter() = default;

void NrrdSliceWriter::write(const void* slices, std::size_t count) {
    Impl& w = *impl_;
    if (w.written + count > w.nz) throw std::logic_error("NrrdSliceWriter::write: too many slices");
    w.out->write(slices, count * w.slice_bytes);
    w.written += count;
}

void NrrdSliceWriter::close() {
    if (impl_->written != impl_->nz) throw std::logic_error("NrrdSliceWriter::close: not every slice was written");
    impl_->out->close();
}

struct SliceWriter::Impl {
    std::unique_ptr<io::NrrdWriter> nrrd;
    std::unique_ptr<io::NiftiWriter> nifti;
    std::size_t slice_bytes = 0;
};

SliceWriter::SliceWriter(const std::string& path, const Dims& dims, ValueType type, const SliceReader& grid)
    : impl_(std::make_unique<Impl>()) {
    impl_->slice_bytes = dims.nx * dims.ny * value_size(type);
    const io::Geometry& g = grid.impl_->geometry;
    if (io::nifti_path(path)) impl_->nifti = std::make_unique<io::NiftiWriter>(path, dims, type, g);
    else impl_->nrrd = std::make_unique<io::NrrdWriter>(path, dims, type, g);
}
SliceWriter::~SliceWriter() = default;
void SliceWriter::write(const void* slices, std::size_t count) {
    if (impl_->nifti) impl_->nifti->write(slices, count * impl_->slice_bytes);
    else impl_->nrrd->write(slices, count * impl_->slice_bytes);
}
void SliceWriter::close() {
    if (impl_->nifti) impl_->nifti->close();
    else impl_->nrrd->close();
}

ValueRange value_range(SliceReader& reader) {
    reader.rewind();
    const Dims d = reader.dims();
    const std::size_t chunk = std::max<std::size_t>(1, std::min(d.nz, (std::size_t(32) << 20) / reader.slice_bytes()));
    ValueRange r;
    bool first = true;
    Volume buf(Dims{d.nx, d.ny, chunk}, reader.type());
    for (std::size_t z = 0; z < d.nz; z += chunk) {
        const std::size_t n = std::min(chunk, d.nz - z);
        if (n != chunk) buf = Volume(Dims{d.nx, d.ny, n}, reader.type());
        reader.read(buf.data(), n);
        const ValueRange c = value_range(buf);
        r.min = first ? c.min : std::min(r.min, c.min);
        r.max = first ? c.max : std::max(r.max, c.max);
        first = false;
    }
    reader.rewind();
    return r;
}

}  // namespace clfractal
