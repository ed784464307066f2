// Test fixtures written by the libraries that own the formats: DICOM slices by GDCM's
// ImageWriter, TIFF pages by libtiff. Used by the formats suite and by clfractal_fixtures
// (the command-line tests' fixture maker).
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace fixtures {

/// One CT slice: stored uint16 values (16 bits stored), axial, PixelSpacing 0.5 (rows) x
/// 0.75 (columns), ImagePositionPatient (-20, 10, z), RescaleSlope/Intercept as given.
struct DicomSlice {
    std::string file, series_uid;
    std::size_t nx = 0, ny = 0;
    std::vector<std::uint16_t> values;
    double z = 0, slope = 1, intercept = 0;
};
/// Writes the slice with GDCM; throws std::runtime_error on failure.
void write_dicom(const DicomSlice& s);

/// One TIFF page: nx*ny samples of `bits` bits in SAMPLEFORMAT `format`, in strips of 3
/// rows or in 16x16 tiles, with a libtiff compression code (1 = none).
struct TiffPage {
    std::uint32_t nx = 0, ny = 0;
    int bits = 8, format = 1;
    const void* data = nullptr;
    bool tiled = false;
    int compression = 1;
};
/// Writes the pages as one (multi-page) TIFF file; throws std::runtime_error on failure.
void write_tiff_pages(const std::string& path, const std::vector<TiffPage>& pages);

}  // namespace fixtures
