// read_volume: one entry for every format, chosen by content (io/detect.cpp), and the
// synthetic:NAME[:N] specs; write_volume: NRRD or NIfTI by the output's extension.
#include "clfractal/volume_io.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <vector>

#include "clfractal/synthetic.hpp"
#include "io/formats.hpp"

namespace fs = std::filesystem;

namespace clfractal {
namespace {

/// synthetic:NAME[:N], N in [2, 2048] (default 128).
Volume read_synthetic(const std::string& spec, std::size_t prefix_length) {
    const std::string rest = spec.substr(prefix_length);
    const std::size_t colon = rest.find(':');
    SyntheticOptions opt;
    if (colon != std::string::npos) {
        const std::string size_text = rest.substr(colon + 1);
        const char* first = size_text.data();
        const char* last = first + size_text.size();
        std::size_t n = 0;
        const auto [next, ec] = std::from_chars(first, last, n);
        if (first == last || ec != std::errc() || next != last || n < 2 || n > 2048)
            throw InputError(spec + ": size '" + size_text +
                             "' must be an integer from 2 to 2048");
        opt.size = n;
    }
    return make_synthetic(rest.substr(0, colon), opt);
}


}  // namespace

Volume read_volume(const std::string& spec, const RawOptions& raw, FiniteCheck finite) {
    const std::string synthetic_prefix = "synthetic:";
    Volume v;
    if (spec.compare(0, synthetic_prefix.size(), synthetic_prefix) == 0) {
        v = read_synthetic(spec, synthetic_prefix.size());
    } else {
        std::error_code ec;
        if (!fs::exists(spec, ec)) throw InputError(spec + ": no such file");
        if (!fs::is_regular_file(spec, ec) && !fs::is_directory(spec, ec))
            throw InputError(spec + ": not a regular file");
        switch (io::detect_format(spec)) {
        case io::Format::nrrd: v = read_nrrd(spec); break;
        case io::Format::nifti: v = io::read_nifti(spec, raw.scaled); break;
        case io::Format::dicom:
        case io::Format::directory_dicom: v = io::read_dicom(spec, raw.series); break;
        case io::Format::tiff:
        case io::Format::directory_tiff: v = io::read_tiff(spec); break;
        case io::Format::metaimage: v = io::read_metaimage(spec); break;
        case io::Format::raw: v = read_raw(spec, raw); break;
        }
    }
    if (finite == FiniteCheck::reject) check_finite(v, spec);
    if (raw.as && *raw.as != v.type()) v = convert_volume(v, *raw.as);
    v.name = spec;
    return v;
}

void write_volume(const Volume& v, const std::string& path, const Volume* grid) {
    std::string ext = fs::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    for (const char* read_only : {".mha", ".mhd", ".tif", ".tiff", ".dcm", ".hdr", ".img"})
        if (ext == read_only)
            throw InputError(path + ": cannot write " + ext + " files; use .nrrd, .nii or .nii.gz");
    const io::Geometry g = io::geometry_of(grid ? *grid : v);
    if (io::nifti_path(path)) {
        io::NiftiWriter w(path, v.dims(), v.type(), g);
        w.write(v.data(), v.size_bytes());
        return w.close();
    }
    io::write_nrrd_grid(v, path, false, g);
}

std::vector<std::string> describe_volume_file(const std::string& spec, const RawOptions& raw) {
    if (spec.rfind("synthetic:", 0) == 0) return {"format    synthetic"};
    std::error_code ec;
    if (!fs::exists(spec, ec)) return {};  // read_volume words it
    const io::Format f = io::detect_format(spec);
    std::vector<std::string> lines{std::string("format    ") + io::format_name(f)};
    std::vector<std::string> notes;
    if (f == io::Format::nifti) notes = io::nifti_notes(spec);
    if (f == io::Format::dicom || f == io::Format::directory_dicom) notes = io::dicom_notes(spec, raw.series);
    for (const std::string& n : notes) lines.push_back("          " + n);
    return lines;
}

}  // namespace clfractal
