// fd --stream and local --stream: a volume file read slice by slice (docs/definitions.md §28),
// so that host memory stays a few slices however large the file.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <vector>

#include "clfractal/analysis.hpp"
#include "clfractal/components.hpp"
#include "clfractal/local.hpp"

#include "clfractal/slice_reader.hpp"
#include "clfractal/stream.hpp"
#include "cli.hpp"

using namespace clfractal;

namespace cli {

StreamedSpans stream_spans(SliceReader& reader, const std::string& volume, const std::string& isovalues,
                           std::size_t bins, int levels, SpanKind kind) {
    const Dims d = reader.dims();
    check_bins(bins, reader.type());
    StreamedSpans out{d, reader.type(), {}, reader.method(), {}};
    IsovalueSet iso;
    // 8- and 16-bit integers without --isovalues: one pass, counting every value of the type
    // and cropping the curves to the value range afterwards (the count at s does not depend
    // on the set); the range is where the histogram of every value is not 0, so it costs no
    // pass of its own over the file.
    const bool crop = isovalues.empty() && is_integer(reader.type()) && !is_wide(reader.type());
    if (!isovalues.empty()) {
        iso = parse_isovalues(isovalues, reader.type());
    } else if (crop) {
        iso = IsovalueSet::integers(std::int64_t(type_min(reader.type())), std::int64_t(type_max(reader.type())));
    } else {
        // The default set needs the value range: one more pass over the file.
        progress("reading the value range of " + volume + " (" + out.method + ")");
        const ValueRange r = value_range(reader);
        iso = IsovalueSet::for_range(reader.type(), r.min, r.max, bins ? bins : 256);
    }
    Context& ctx = Context::shared();
    progress("streaming " + std::to_string(iso.size()) + " isovalues" +
             (crop ? " (every " + std::string(value_type_name(reader.type())) + " value, cropped to the range at the end)"
                   : std::string()) +
             " of " + dims_string(d) + " " +
             value_type_name(reader.type()) + " slice by slice (" + out.method + ") on " + ctx.description());
    SpanStream stream(ctx, d.nx, d.ny, reader.type(), iso, levels, {kind});
    out.histogram.assign(iso.size(), 0);
    // Slices are read straight into the stream's batch buffer, as many as it has room for.
    for (std::size_t z = 0; z < d.nz;) {
        std::size_t room = 0;
        void* slices = stream.next_slices(room);
        const std::size_t n = std::min(room, d.nz - z);
        reader.read(slices, n);
        // The vertices at each isovalue (boundary strength), batch by batch, as in core.
        const std::vector<std::uint64_t> h =
            isovalue_histogram(Volume::wrap(slices, Dims{d.nx, d.ny, n}, reader.type()), iso);
        for (std::size_t k = 0; k < h.size(); ++k) out.histogram[k] += h[k];
        stream.push_filled(n);
        z += n;
    }
    out.spans = stream.counts();
    if (crop && d.vertices()) {
        const std::vector<std::uint64_t>& hist = out.histogram;
        const auto nonzero = [](std::uint64_t c) { return c != 0; };
        const auto from = std::find_if(hist.begin(), hist.end(), nonzero) - hist.begin();
        const auto to = hist.rend() - std::find_if(hist.rbegin(), hist.rend(), nonzero);
        out.spans.isovalues = IsovalueSet::integers(iso.first() + from, iso.first() + to - 1);
        for (SpanCurves& c : out.spans.curves)
            for (auto& level : c.counts) level = std::vector<std::uint64_t>(level.begin() + from, level.begin() + to);
        // No value lies outside the range, so the cropped bins are the whole histogram.
        out.histogram = std::vector<std::uint64_t>(hist.begin() + from, hist.begin() + to);
    }
    return out;
}

std::vector<std::int64_t> stream_components_at(SliceReader& reader, const std::vector<double>& isovalues,
                                               Connectivity mode) {
    const Dims d = reader.dims();
    if (d.nx == 0 || d.ny == 0 || d.nz == 0) return std::vector<std::int64_t>(isovalues.size(), 0);
    ComponentsAtStream stream(d.nx, d.ny, reader.type(), isovalues, mode);
    // Batches of up to 32 MiB, read into one reused buffer.
    const std::size_t batch = std::clamp<std::size_t>((std::size_t(32) << 20) / reader.slice_bytes(), 1, d.nz);
    std::vector<unsigned char> slices(batch * reader.slice_bytes());
    for (std::size_t z = reader.next_slice(); z < d.nz; z += batch) {
        const std::size_t n = std::min(batch, d.nz - z);
        reader.read(slices.data(), n);
        stream.push_slices(slices.data(), n);
    }
    return stream.counts();
}

int cmd_local_stream(const std::string& volume, const RawOptions& raw, double iso, int window,
                     const std::string& output) {
    SliceReader reader(volume, raw);
    const Dims d = reader.dims();
    Context& ctx = Context::shared();
    progress("local fractal dimension of " + dims_string(d) + " " + value_type_name(reader.type()) +
             " slice by slice (" + reader.method() + "), window " + std::to_string(window) + ", on " +
             ctx.description());
    const auto t0 = std::chrono::steady_clock::now();
    SliceWriter writer(output, d, ValueType::float32, reader);
    std::size_t defined = 0, above_blue = 0, above_red = 0;
    double sum = 0;
    const std::size_t plane = d.nx * d.ny;
    // Output slices come a few at a time, k/2 slices behind the input.
    LocalStream stream(
        ctx, d.nx, d.ny, reader.type(), iso, window,
        [&](std::size_t, const float* ld, const void*) {
            for (std::size_t i = 0; i < plane; ++i) {
                if (std::isnan(ld[i])) continue;
                ++defined;
                above_blue += ld[i] > ld_blue;
                above_red += ld[i] > ld_red;
                sum += ld[i];
            }
            writer.write(ld, 1);
        },
        std::max<std::size_t>(1, std::min<std::size_t>(16, (std::size_t(64) << 20) / (plane * 4))));
    std::vector<unsigned char> slice(reader.slice_bytes());
    for (std::size_t z = 0; z < d.nz; ++z) {
        reader.read(slice.data(), 1);
        stream.push_slice(static_cast<const void*>(slice.data()));
    }
    stream.finish();
    writer.close();
    const double seconds = seconds_since(t0);

    const double vertices = double(d.vertices());
    std::cout << "volume      " << volume << "  " << dims_string(d) << " " << value_type_name(reader.type()) << "\n"
              << "device      " << ctx.description() << "\n"
              << "isovalue    " << iso << compared_as(reader.type()) << ", window "
              << window << "\n"
              << std::fixed << std::setprecision(2) << "defined     " << defined << " of " << d.vertices()
              << " vertices (" << 100.0 * double(defined) / vertices << "%, near the surface)\n";
    if (defined)
        std::cout << "LD > 2.2    " << 100.0 * double(above_blue) / double(defined)
                  << "% of them (colour map: blue up to 2.2)\n"
                  << "LD > 2.5    " << 100.0 * double(above_red) / double(defined) << "% of them (red from 2.5)\n"
                  << std::setprecision(4) << "mean LD     " << sum / double(defined) << "\n";
    else
        std::cout << "mean LD     n/a (the isovalue intersects no window)\n";
    std::cout << std::defaultfloat << std::setprecision(4) << "time        " << seconds
              << " s (streamed, " << reader.method() << ", read and written slice by slice), kernels compiled in "
              << ctx.compile_seconds() << " s\n"
              << "wrote       " << output << " (float32, NaN where LD is undefined)\n";
    return 0;
}

}  // namespace cli
