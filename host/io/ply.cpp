// Binary little-endian PLY files of meshes: the layout write_ply writes and read_ply reads
// back (triangles only), written through a temporary file renamed into place.
#include "clfractal/ply.hpp"

#include <cstring>
#include <fstream>
#include <limits>
#include <stdexcept>

#include "io/output_file.hpp"

namespace clfractal {
namespace {


void put_u32(std::string& out, std::uint32_t v) {
    for (int b = 0; b < 4; ++b) out.push_back(char((v >> (8 * b)) & 0xff));
}
void put_f32(std::string& out, float f) {
    std::uint32_t v;
    std::memcpy(&v, &f, 4);
    put_u32(out, v);
}
std::uint32_t get_u32(const unsigned char* p) {
    return std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 | std::uint32_t(p[3]) << 24;
}
float get_f32(const unsigned char* p) {
    const std::uint32_t v = get_u32(p);
    float f;
    std::memcpy(&f, &v, 4);
    return f;
}

}  // namespace

void write_ply(const Mesh& mesh, const std::string& path) {
    const bool colors = !mesh.colors.empty(), ld = !mesh.ld.empty();
    if ((colors && mesh.colors.size() != mesh.positions.size()) || (ld && mesh.ld.size() != mesh.positions.size()))
        throw std::logic_error("write_ply: per-vertex arrays differ in size from the positions");

    std::string header = "ply\nformat binary_little_endian 1.0\ncomment written by clfractal\nelement vertex " +
                         std::to_string(mesh.positions.size()) + "\nproperty float x\nproperty float y\nproperty float z\n";
    if (colors) header += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
    if (ld) header += "property float ld\n";
    header += "element face " + std::to_string(mesh.triangles.size()) +
              "\nproperty list uchar int vertex_indices\nend_header\n";

    const std::string tmp = temporary_path(path);
    std::ofstream out(tmp, std::ios::binary);
    out << header;
    std::string record;
    for (std::size_t i = 0; i < mesh.positions.size() && out; ++i) {
        record.clear();
        for (float c : mesh.positions[i]) put_f32(record, c);
        if (colors) record.append(mesh.colors[i].begin(), mesh.colors[i].end());
        if (ld) put_f32(record, mesh.ld[i]);
        out.write(record.data(), std::streamsize(record.size()));
    }
    for (std::size_t i = 0; i < mesh.triangles.size() && out; ++i) {
        record.assign(1, char(3));
        for (std::uint32_t k : mesh.triangles[i]) put_u32(record, k);
        out.write(record.data(), std::streamsize(record.size()));
    }
    out.close();
    if (!out) discard_temporary(tmp, path, "cannot write (directory missing or not writable?)");
    rename_into_place(tmp, path);
}

namespace {

// What a clfractal PLY header declares.
struct PlyHeader {
    std::size_t nv = 0, nf = 0;
    bool colors = false, ld = false;
};

InputError not_clfractal_ply(const std::string& path, const std::string& what) {
    return InputError(path + ": not a clfractal PLY file: " + what);
}

// Read and check the header up to end_header; `in` is left at the first data byte.
PlyHeader read_ply_header(std::istream& in, const std::string& path) {
    auto bad = [&](const std::string& what) { return not_clfractal_ply(path, what); };
    std::vector<std::string> lines;
    for (std::string line; std::getline(in, line) && line != "end_header";) {
        if (line.rfind("comment", 0) != 0) lines.push_back(line);
        if (lines.size() > 32) throw bad("header too long");
    }
    if (!in) throw bad("no end_header");
    std::size_t k = 0;
    auto expect = [&](const std::string& line) {
        if (k >= lines.size() || lines[k] != line) throw bad("expected '" + line + "'");
        ++k;
    };
    auto element = [&](const std::string& name) {
        const std::string prefix = "element " + name + " ";
        if (k >= lines.size() || lines[k].rfind(prefix, 0) != 0) throw bad("expected '" + prefix + "N'");
        const std::string n = lines[k++].substr(prefix.size());
        if (n.empty() || n.size() > 10 || n.find_first_not_of("0123456789") != std::string::npos)
            throw bad("bad count '" + n + "'");
        return std::size_t(std::stoull(n));
    };
    PlyHeader h;
    expect("ply");
    expect("format binary_little_endian 1.0");
    h.nv = element("vertex");
    expect("property float x");
    expect("property float y");
    expect("property float z");
    h.colors = k < lines.size() && lines[k] == "property uchar red";
    if (h.colors) {
        expect("property uchar red");
        expect("property uchar green");
        expect("property uchar blue");
    }
    h.ld = k < lines.size() && lines[k] == "property float ld";
    if (h.ld) expect("property float ld");
    h.nf = element("face");
    expect("property list uchar int vertex_indices");
    if (k != lines.size()) throw bad("unexpected '" + lines[k] + "'");
    return h;
}

// Decode the vertex and face records the header declares.
Mesh decode_ply_data(const std::vector<unsigned char>& data, const PlyHeader& h, const std::string& path) {
    const std::size_t nv = h.nv, nf = h.nf;
    const bool colors = h.colors, ld = h.ld;
    Mesh mesh;
    const unsigned char* p = data.data();
    mesh.positions.resize(nv);
    if (colors) mesh.colors.resize(nv);
    if (ld) mesh.ld.resize(nv);
    for (std::size_t i = 0; i < nv; ++i) {
        for (int a = 0; a < 3; ++a, p += 4) mesh.positions[i][a] = get_f32(p);
        if (colors) {
            std::copy(p, p + 3, mesh.colors[i].begin());
            p += 3;
        }
        if (ld) {
            mesh.ld[i] = get_f32(p);
            p += 4;
        }
    }
    mesh.triangles.resize(nf);
    for (std::size_t i = 0; i < nf; ++i) {
        if (*p++ != 3) throw InputError(path + ": face " + std::to_string(i) + " is not a triangle");
        for (int a = 0; a < 3; ++a, p += 4) {
            const std::uint32_t id = get_u32(p);
            if (id >= nv) throw InputError(path + ": face " + std::to_string(i) + " has vertex index out of range");
            mesh.triangles[i][a] = id;
        }
    }
    return mesh;
}

}  // namespace

Mesh read_ply(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path + ": cannot open");
    const PlyHeader h = read_ply_header(in, path);
    const std::size_t nv = h.nv, nf = h.nf;

    // Check the sizes against the file before allocating anything.
    const std::size_t vertex_bytes = 12 + (h.colors ? 3 : 0) + (h.ld ? 4 : 0), face_bytes = 13;
    const auto start = in.tellg();
    in.seekg(0, std::ios::end);
    const std::size_t available = std::size_t(in.tellg() - start);
    in.seekg(start);
    if (nv * vertex_bytes + nf * face_bytes != available)
        throw InputError(path + ": truncated or oversized PLY (" + std::to_string(available) + " data bytes, header says " +
                         std::to_string(nv * vertex_bytes + nf * face_bytes) + ")");
    std::vector<unsigned char> data(available);
    in.read(reinterpret_cast<char*>(data.data()), std::streamsize(available));
    if (!in) throw InputError(path + ": read error");
    return decode_ply_data(data, h, path);
}

}  // namespace clfractal
