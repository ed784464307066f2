// Fixture writers (format_fixtures.hpp).
#include "format_fixtures.hpp"

#include <gdcmAttribute.h>
#include <gdcmImage.h>
#include <gdcmImageWriter.h>
#include <gdcmTrace.h>
#include <tiffio.h>

#include <algorithm>
#include <cstring>
#include <stdexcept>

namespace fixtures {

// ---------------------------------------------------------------- DICOM (GDCM writes)


void write_dicom(const DicomSlice& s) {
    gdcm::Trace::SetWarning(false);
    gdcm::ImageWriter w;
    gdcm::Image& im = w.GetImage();
    im.SetNumberOfDimensions(2);
    im.SetDimension(0, unsigned(s.nx));
    im.SetDimension(1, unsigned(s.ny));
    im.SetPixelFormat(gdcm::PixelFormat(1, 16, 16, 15, 0));
    im.SetPhotometricInterpretation(gdcm::PhotometricInterpretation::MONOCHROME2);
    im.SetSpacing(0, 0.75);  // column spacing: x
    im.SetSpacing(1, 0.5);   // row spacing: y
    im.SetSpacing(2, 1.0);
    im.SetOrigin(0, -20.0);
    im.SetOrigin(1, 10.0);
    im.SetOrigin(2, s.z);
    const double cosines[6] = {1, 0, 0, 0, 1, 0};
    im.SetDirectionCosines(cosines);
    im.SetSlope(s.slope);
    im.SetIntercept(s.intercept);
    gdcm::DataElement pixels(gdcm::Tag(0x7fe0, 0x0010));
    pixels.SetByteValue(reinterpret_cast<const char*>(s.values.data()), std::uint32_t(s.values.size() * 2));
    im.SetDataElement(pixels);
    gdcm::DataSet& ds = w.GetFile().GetDataSet();
    gdcm::Attribute<0x0008, 0x0016> sop_class = {"1.2.840.10008.5.1.4.1.1.2"};  // CT Image Storage
    gdcm::Attribute<0x0008, 0x0060> modality = {"CT"};
    gdcm::Attribute<0x0020, 0x000e> series = {s.series_uid.c_str()};
    ds.Replace(sop_class.GetAsDataElement());
    ds.Replace(modality.GetAsDataElement());
    ds.Replace(series.GetAsDataElement());
    w.SetFileName(s.file.c_str());
    if (!w.Write()) throw std::runtime_error(s.file + ": GDCM cannot write the slice");
}

// ---------------------------------------------------------------- TIFF (libtiff writes)


void write_tiff_pages(const std::string& path, const std::vector<TiffPage>& pages) {
    TIFF* t = TIFFOpen(path.c_str(), "w");
    if (!t) throw std::runtime_error(path + ": libtiff cannot create the file");
    for (const TiffPage& p : pages) {
        TIFFSetField(t, TIFFTAG_IMAGEWIDTH, p.nx);
        TIFFSetField(t, TIFFTAG_IMAGELENGTH, p.ny);
        TIFFSetField(t, TIFFTAG_BITSPERSAMPLE, p.bits);
        TIFFSetField(t, TIFFTAG_SAMPLEFORMAT, p.format);
        TIFFSetField(t, TIFFTAG_SAMPLESPERPIXEL, 1);
        TIFFSetField(t, TIFFTAG_PHOTOMETRIC, PHOTOMETRIC_MINISBLACK);
        TIFFSetField(t, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
        TIFFSetField(t, TIFFTAG_COMPRESSION, p.compression);
        TIFFSetField(t, TIFFTAG_SUBFILETYPE, FILETYPE_PAGE);
        const std::size_t vs = std::size_t(p.bits / 8), row = p.nx * vs;
        const auto* bytes = static_cast<const unsigned char*>(p.data);
        if (p.tiled) {
            const std::uint32_t tw = 16, th = 16;
            TIFFSetField(t, TIFFTAG_TILEWIDTH, tw);
            TIFFSetField(t, TIFFTAG_TILELENGTH, th);
            std::vector<unsigned char> tile(tw * th * vs);
            for (std::uint32_t y = 0; y < p.ny; y += th)
                for (std::uint32_t x = 0; x < p.nx; x += tw) {
                    std::fill(tile.begin(), tile.end(), 0);
                    for (std::uint32_t r = 0; r < th && y + r < p.ny; ++r)
                        std::memcpy(&tile[r * tw * vs], bytes + (y + r) * row + x * vs, std::min(tw, p.nx - x) * vs);
                    if (TIFFWriteTile(t, tile.data(), x, y, 0, 0) < 0) throw std::runtime_error(path + ": cannot write a tile");
                }
        } else {
            TIFFSetField(t, TIFFTAG_ROWSPERSTRIP, 3);
            for (std::uint32_t y = 0; y < p.ny; ++y)
                if (TIFFWriteScanline(t, const_cast<unsigned char*>(bytes + y * row), y, 0) < 0)
                    throw std::runtime_error(path + ": cannot write a row");
        }
        if (!TIFFWriteDirectory(t)) throw std::runtime_error(path + ": cannot write a page");
    }
    TIFFClose(t);
}

}  // namespace fixtures
