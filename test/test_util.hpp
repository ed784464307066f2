// Helpers shared by the test suites.
#pragma once
#include <doctest/doctest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "clfractal/device.hpp"
#include "clfractal/fd.hpp"
#include "clfractal/error.hpp"
#include "clfractal/volume.hpp"

namespace testutil {

inline clfractal::Context& ctx() { return clfractal::Context::shared(); }

/// A volume of uniform random integers in [lo, hi] (float data: integers / 2, so that
/// ties and exact isovalue hits are common), from a fixed seed.
inline clfractal::Volume random_volume(clfractal::Dims d, clfractal::ValueType t, long lo, long hi,
                                       std::uint32_t seed) {
    clfractal::Volume v(d, t);
    std::mt19937 rng(seed);
    std::uniform_int_distribution<long> dist(lo, hi);
    clfractal::visit(v, [&](auto* p) {
        using T = std::remove_pointer_t<decltype(p)>;
        for (std::size_t i = 0; i < v.vertices(); ++i) {
            long x = dist(rng);
            p[i] = std::is_floating_point<T>::value ? T(double(x) / 2) : T(x);
        }
    });
    return v;
}

/// A row of a table of random test volumes: dims, value type and the range [lo, hi] of the
/// random integers (float data holds them / 2: random_volume).
struct Case {
    clfractal::Dims d;
    clfractal::ValueType t;
    long lo, hi;
};

/// Whether `text` contains `part`.
inline bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

/// The message of the InputError thrown by f, checked to be one line; fails the test when
/// none is thrown.
template <class F> std::string input_error(F&& f) {
    try {
        f();
    } catch (const clfractal::InputError& e) {
        const std::string message = e.what();
        CHECK_MESSAGE(message.find('\n') == std::string::npos, "not one line: ", message);
        return message;
    }
    FAIL_CHECK("no InputError thrown");
    return {};
}

/// Checks that two volumes have the same dims, type and bytes.
inline void check_same(const clfractal::Volume& a, const clfractal::Volume& b) {
    REQUIRE(a.dims() == b.dims());
    REQUIRE(a.type() == b.type());
    REQUIRE(a.size_bytes() == b.size_bytes());
    CHECK(std::memcmp(a.data(), b.data(), a.size_bytes()) == 0);
}

/// Restores the shared context's tuning when it goes out of scope.
struct TuningGuard {
    clfractal::Tuning saved = ctx().tuning;
    ~TuningGuard() { ctx().tuning = saved; }
};

/// The directory of real benchmark volumes, or "" when absent.
inline std::string shared_data() {
#ifdef CLFRACTAL_SHARED_DATA
    if (std::filesystem::exists(std::string(CLFRACTAL_SHARED_DATA) + "/MANIFEST.tsv")) return CLFRACTAL_SHARED_DATA;
#endif
    return "";
}

/// The shared data directory, or "" after a test message that `what` is skipped.
inline std::string shared_data_or_skip(const std::string& what) {
    const std::string dir = shared_data();
    if (dir.empty()) MESSAGE("../shared/data is absent: " << what << " skipped");
    return dir;
}

/// One volume of the shared data's MANIFEST.tsv: its path and its row by column name
/// (file, name, dims, dtype, category, ...).
struct RealVolume {
    std::string path;
    std::map<std::string, std::string> columns;
    const std::string& file() const { return columns.at("file"); }
};

/// The volumes of MANIFEST.tsv in its order, or none after a test message that `what` is
/// skipped when the shared data is absent.
inline std::vector<RealVolume> real_volumes(const std::string& what) {
    const std::string dir = shared_data_or_skip(what);
    std::vector<RealVolume> out;
    if (dir.empty()) return out;
    const auto split = [](const std::string& text) {
        std::vector<std::string> cells;
        std::stringstream ss(text);
        for (std::string cell; std::getline(ss, cell, '\t');) cells.push_back(cell);
        return cells;
    };
    std::ifstream manifest(dir + "/MANIFEST.tsv");
    std::string line;
    std::getline(manifest, line);
    const std::vector<std::string> header = split(line);
    while (std::getline(manifest, line)) {
        const std::vector<std::string> row = split(line);
        RealVolume v;
        for (std::size_t c = 0; c < header.size() && c < row.size(); ++c) v.columns[header[c]] = row[c];
        if (v.columns["file"].empty()) continue;
        v.path = dir + "/" + v.columns["file"];
        out.push_back(v);
    }
    return out;
}

/// A curve over the integer isovalues 0..n-1 with the given D and the same counts on both
/// levels.
inline clfractal::FdCurve curve(const std::vector<double>& fd, const std::vector<std::uint64_t>& count) {
    clfractal::FdCurve f;
    f.isovalues = clfractal::IsovalueSet::integers(0, std::int64_t(fd.size()) - 1);
    f.fd = fd;
    f.counts = {count, count};
    return f;
}

}  // namespace testutil
