// fd --stream: span counts of a volume file read slice by slice (DESIGN §6), so that host
// memory stays a few slices however large the file.
#include <algorithm>
#include <vector>

#include "clfractal/slice_reader.hpp"
#include "clfractal/stream.hpp"
#include "cli.hpp"

using namespace clfractal;

namespace cli {

StreamedSpans stream_spans(const std::string& volume, const RawOptions& raw, const std::string& isovalues,
                           std::size_t bins, int levels, SpanKind kind) {
    SliceReader reader(volume, raw);
    const Dims d = reader.dims();
    if (bins && is_integer(reader.type()))
        throw InputError("--bins: integer data uses every integer isovalue; use --isovalues A:B:1 to select");
    StreamedSpans out{d, reader.type(), {}, reader.method()};
    IsovalueSet iso;
    if (!isovalues.empty()) {
        iso = IsovalueSet::parse_range(isovalues, reader.type());
    } else {
        // The default set needs the value range: one more pass over the file.
        progress("reading the value range of " + volume + " (" + out.method + ")");
        const ValueRange r = value_range(reader);
        iso = is_integer(reader.type()) ? IsovalueSet::integers(std::int64_t(r.min), std::int64_t(r.max))
                                        : IsovalueSet::uniform(r.min, r.max, bins ? bins : 256);
    }
    Context& ctx = Context::shared();
    progress("streaming " + std::to_string(iso.size()) + " isovalues of " + dims_string(d) + " " +
             value_type_name(reader.type()) + " slice by slice (" + out.method + ") on " + ctx.description());
    SpanStream stream(ctx, d.nx, d.ny, reader.type(), iso, levels, {kind});
    // Read a batch of slices at a time; the stream copies each slice into its own batch.
    const std::size_t chunk = std::max<std::size_t>(1, std::min(d.nz, stream.batch_slices()));
    std::vector<unsigned char> buf(chunk * reader.slice_bytes());
    for (std::size_t z = 0; z < d.nz;) {
        const std::size_t n = std::min(chunk, d.nz - z);
        reader.read(buf.data(), n);
        for (std::size_t i = 0; i < n; ++i) stream.push_slice(static_cast<const void*>(buf.data() + i * reader.slice_bytes()));
        z += n;
    }
    out.spans = stream.counts();
    return out;
}

}  // namespace cli
