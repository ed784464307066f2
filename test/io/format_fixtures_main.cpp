// clfractal_fixtures: writes a volume as a DICOM series (GDCM) or TIFF (libtiff), for the
// command-line tests (formats_cli_test.sh).
//   clfractal_fixtures dicom VOLUME OUTDIR UID INTERCEPT   uint16 volume, files in shuffled order
//   clfractal_fixtures tiff VOLUME OUT.tif                 one page per slice, LZW strips
//   clfractal_fixtures tiffdir VOLUME OUTDIR               one tiled deflate file per slice
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <numeric>
#include <random>

#include "clfractal/volume_io.hpp"
#include "format_fixtures.hpp"

using namespace clfractal;

int main(int argc, char** argv) {
    try {
        const std::string what = argc > 3 ? argv[1] : "";
        if (what.empty() || (what == "dicom" && argc != 6)) {
            std::cerr << "usage: clfractal_fixtures dicom|tiff|tiffdir VOLUME OUT [UID INTERCEPT]\n";
            return 2;
        }
        const Volume v = read_volume(argv[2]);
        const std::string out = argv[3];
        const Dims d = v.dims();
        const std::size_t plane = d.nx * d.ny, bytes = plane * value_size(v.type());
        const auto* data = static_cast<const unsigned char*>(v.data());
        if (what == "dicom") {
            if (v.type() != ValueType::uint16) throw InputError(std::string(argv[2]) + ": dicom needs uint16 data");
            std::filesystem::create_directories(out);
            std::vector<std::size_t> order(d.nz);
            std::iota(order.begin(), order.end(), 0);
            std::shuffle(order.begin(), order.end(), std::mt19937(5));
            for (std::size_t k = 0; k < d.nz; ++k) {
                const std::size_t z = order[k];
                fixtures::DicomSlice s{out + "/" + argv[4] + "_" + std::to_string(k) + ".dcm", argv[4], d.nx, d.ny, {},
                                       3.0 * double(z), 1.0, std::atof(argv[5])};
                const std::uint16_t* p = v.as<std::uint16_t>() + z * plane;
                s.values.assign(p, p + plane);
                fixtures::write_dicom(s);
            }
            return 0;
        }
        const int bits = int(value_size(v.type())) * 8;
        const int format = v.type() == ValueType::float32 ? 3 : v.type() == ValueType::int16 ? 2 : 1;
        if (what == "tiff") {
            std::vector<fixtures::TiffPage> pages;
            for (std::size_t z = 0; z < d.nz; ++z)
                pages.push_back({std::uint32_t(d.nx), std::uint32_t(d.ny), bits, format, data + z * bytes, false, 5});
            fixtures::write_tiff_pages(out, pages);
            return 0;
        }
        if (what == "tiffdir") {
            std::filesystem::create_directories(out);
            for (std::size_t z = 0; z < d.nz; ++z)
                fixtures::write_tiff_pages(out + "/slice" + std::to_string(z + 1) + ".tif",
                                           {{std::uint32_t(d.nx), std::uint32_t(d.ny), bits, format, data + z * bytes,
                                             true, 8}});
            return 0;
        }
        std::cerr << "clfractal_fixtures: unknown kind " << what << "\n";
        return 2;
    } catch (const std::exception& e) {
        std::cerr << "clfractal_fixtures: " << e.what() << "\n";
        return 1;
    }
}
