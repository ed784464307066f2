// Volume layer: value types, dims checks, volumes, host storage, value statistics.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "clfractal/memory.hpp"
#include "clfractal/volume.hpp"
#include "test_util.hpp"

using namespace clfractal;
using testutil::contains;
using testutil::input_error;

namespace {

const auto& all_types = all_value_types;

}  // namespace

TEST_SUITE("volume") {

TEST_CASE("value types: sizes, names, parsing") {
    CHECK(value_size(ValueType::uint8) == 1);
    CHECK(value_size(ValueType::uint16) == 2);
    CHECK(value_size(ValueType::int16) == 2);
    CHECK(value_size(ValueType::float32) == 4);
    CHECK(value_size(ValueType::int8) == 1);
    CHECK(value_size(ValueType::int32) == 4);
    CHECK(value_size(ValueType::uint32) == 4);
    CHECK(value_size(ValueType::float64) == 8);
    CHECK(std::size(all_value_types) == 8);
    for (ValueType t : all_types) CHECK(parse_value_type(value_type_name(t)) == t);
    for (ValueType t : all_types) CHECK(parse_value_type(opencl_type_name(t)) == t);
    CHECK(std::string(opencl_type_name(ValueType::int8)) == "char");
    CHECK(std::string(opencl_type_name(ValueType::uint32)) == "uint");
    CHECK(std::string(opencl_type_name(ValueType::float64)) == "double");
    CHECK(std::string(nrrd_type_name(ValueType::int8)) == "signed char");
    CHECK(std::string(nrrd_type_name(ValueType::uint32)) == "unsigned int");
    CHECK(type_min(ValueType::int8) == -128);
    CHECK(type_max(ValueType::uint32) == 4294967295.0);
    CHECK(type_min(ValueType::int32) == -2147483648.0);
    CHECK(is_integer(ValueType::int8));
    CHECK(is_integer(ValueType::uint32));
    CHECK_FALSE(is_integer(ValueType::float64));
    CHECK(is_wide(ValueType::int32));
    CHECK(is_wide(ValueType::float64));
    CHECK_FALSE(is_wide(ValueType::int16));
    CHECK_FALSE(is_wide(ValueType::float32));
    CHECK(contains(input_error([] { parse_value_type("int64"); }), "int64"));
    CHECK(contains(input_error([] { parse_value_type("int64"); }), "float64"));
    CHECK(parse_value_type("uchar") == ValueType::uint8);
    CHECK(parse_value_type("ushort") == ValueType::uint16);
    CHECK(parse_value_type("short") == ValueType::int16);
    CHECK(parse_value_type("float") == ValueType::float32);
    CHECK(is_integer(ValueType::int16));
    CHECK_FALSE(is_integer(ValueType::float32));
}

TEST_CASE("dims: cubes and check_dims") {
    CHECK(Dims{4, 5, 6}.cubes() == 3 * 4 * 5);
    CHECK(Dims{1, 5, 6}.cubes() == 0);
    CHECK(dims_string(Dims{4, 5, 6}) == "4x5x6");
    CHECK_NOTHROW(check_dims(Dims{1, 1, 1}, "v"));
    CHECK_NOTHROW(check_dims(Dims{std::size_t(1) << 20, std::size_t(1) << 20, 1}, "v"));
    CHECK(input_error([] { check_dims(Dims{100000, 100000, 100000}, "VOLUME"); }) ==
          "VOLUME: dims 100000x100000x100000 exceed the maximum of 2^40 vertices");
    CHECK(contains(input_error([] { check_dims(Dims{0, 4, 4}, "VOLUME"); }), "VOLUME: dims 0x4x4"));
    // Products that wrap around 2^64 must not slip through.
    const std::size_t big = std::size_t(1) << 32;
    CHECK(contains(input_error([&] { check_dims(Dims{big, big, big}, "V"); }), "exceed"));
    CHECK(contains(input_error([&] { check_dims(Dims{big, big, 1}, "V"); }), "exceed"));
    CHECK(contains(input_error([&] { check_dims(Dims{SIZE_MAX, SIZE_MAX, 2}, "V"); }), "exceed"));
    CHECK(contains(input_error([&] { Volume(Dims{big, big, big}, ValueType::uint8, "huge"); }), "huge"));
}

TEST_CASE("Volume: zero-filled, typed access, values, range") {
    Volume v(Dims{3, 4, 5}, ValueType::int16, "v");
    CHECK(v.vertices() == 60);
    CHECK(v.size_bytes() == 120);
    CHECK(v.name == "v");
    CHECK(v.spacing == std::array<double, 3>{1.0, 1.0, 1.0});
    const std::int16_t* p = v.as<std::int16_t>();
    CHECK(std::all_of(p, p + 60, [](std::int16_t x) { return x == 0; }));
    CHECK_THROWS_AS(v.as<float>(), std::logic_error);
    v.as<std::int16_t>()[v.index(2, 3, 4)] = -7;
    v.as<std::int16_t>()[v.index(1, 0, 0)] = 300;
    CHECK(v.value(59) == -7);
    CHECK(v.value(1) == 300);
    const ValueRange r = value_range(v);
    CHECK(r.min == -7);
    CHECK(r.max == 300);
    CHECK(value_range(Volume{}).min == 0);
}

TEST_CASE("host storage: page-aligned, zero, copies are deep") {
    // (From 32 MiB on the pages are mapped by every core.)
    for (std::size_t n : {std::size_t(1), std::size_t(4095), std::size_t(1) << 20, (std::size_t(3) << 20) + 5,
                          std::size_t(32) << 20, (std::size_t(41) << 20) + 4097}) {
        CAPTURE(n);
        HostBytes b(n);
        REQUIRE(b.size() == n);
        CHECK(reinterpret_cast<std::uintptr_t>(b.data()) % 4096 == 0);
        CHECK(std::all_of(b.data(), b.data() + n, [](unsigned char c) { return c == 0; }));
        b.data()[n - 1] = 7;
        HostBytes c(b);
        c.data()[n - 1] = 9;
        CHECK(b.data()[n - 1] == 7);
        HostBytes m(std::move(c));
        CHECK(m.data()[n - 1] == 9);
        CHECK(c.size() == 0);
        b = m;
        CHECK(b.data()[n - 1] == 9);
    }
    Volume v({300, 300, 13}, ValueType::float32, "big");
    const Volume w = v;
    CHECK(w.data() != v.data());
    CHECK(value_range(w).max == 0);
}

TEST_CASE("wrapped volumes read the caller's values in place; copies own theirs") {
    std::vector<std::uint16_t> values(3 * 4 * 5);
    for (std::size_t i = 0; i < values.size(); ++i) values[i] = std::uint16_t(i * 7);
    {
        Volume v = Volume::wrap(values.data(), {3, 4, 5}, ValueType::uint16, "array");
        CHECK(v.wrapped());
        CHECK(v.data() == values.data());
        CHECK(v.value(v.index(2, 3, 4)) == double(values.back()));
        Volume copy = v;
        CHECK_FALSE(copy.wrapped());
        CHECK(copy.data() != values.data());
        values[0] = 1;
        CHECK(v.value(0) == 1);
        CHECK(copy.value(0) == 0);
        Volume moved = std::move(v);
        CHECK(moved.wrapped());
        CHECK(moved.data() == values.data());
    }  // destroyed without freeing the caller's values
    CHECK(values[1] == 7);
    CHECK(contains(input_error([&] { Volume::wrap(values.data(), {0, 4, 5}, ValueType::uint16, "array"); }), "array"));
}

TEST_CASE("value stats: one pass finds the finite range and counts NaN and Inf, every type") {
    std::uint32_t seed = 40;
    for (ValueType t : all_value_types)
        for (std::size_t n : {std::size_t(1), std::size_t(17), std::size_t(40000)}) {
            CAPTURE(value_type_name(t));
            CAPTURE(n);
            Volume v = testutil::random_volume({n, 1, 1}, t, -100, 100, seed++);
            std::size_t nan = 0, inf = 0;
            if (!is_integer(t) && n > 2) {
                visit(v, [&](auto* p) {
                    using T = std::remove_pointer_t<decltype(p)>;
                    if constexpr (std::is_floating_point_v<T>) {
                        p[n / 2] = std::numeric_limits<T>::quiet_NaN();
                        p[n - 1] = -std::numeric_limits<T>::infinity();
                        p[0] = -std::numeric_limits<T>::quiet_NaN();
                    }
                });
                nan = 2;
                inf = 1;
            }
            double lo = INFINITY, hi = -INFINITY;
            for (std::size_t i = 0; i < n; ++i)
                if (std::isfinite(v.value(i))) lo = std::min(lo, v.value(i)), hi = std::max(hi, v.value(i));
            const ValueStats s = value_stats(v);
            CHECK(s.nan == nan);
            CHECK(s.inf == inf);
            CHECK(s.min == lo);
            CHECK(s.max == hi);
            // info's summary: the same range, and a histogram and mean as a plain loop gives them.
            const ValueSummary sum = summarize_values(v, 16);
            CHECK(sum.stats.min == lo);
            CHECK(sum.stats.max == hi);
            CHECK(sum.finite == n - nan - inf);
            std::vector<std::size_t> h(16, 0);
            double total = 0;
            for (std::size_t i = 0; i < n; ++i) {
                const double x = v.value(i);
                if (!std::isfinite(x)) continue;
                total += x;
                const double w = (hi - lo) / 16;
                ++h[std::size_t(w > 0 ? std::min(int((x - lo) / w), 15) : 0)];
            }
            CHECK(sum.histogram == h);
            CHECK(sum.mean == doctest::Approx(total / double(sum.finite)));
        }
    const ValueStats none = value_stats(nullptr, ValueType::float32, 0);
    CHECK(none.min == 0);
    CHECK(none.nan == 0);
}

TEST_CASE("memory: byte counts, sizes and the check before work") {
    CHECK(parse_byte_count("4096", "x") == 4096u);
    CHECK(parse_byte_count("512M", "x") == 512ull << 20);
    CHECK(parse_byte_count("512 MiB", "x") == 512ull << 20);
    CHECK(parse_byte_count("1.5G", "x") == 3ull << 29);
    CHECK(parse_byte_count("2t", "x") == 2ull << 40);
    for (const char* bad : {"", "lots", "-1", "5X", "1e30", "nan", "4 4"})
        CHECK_THROWS_WITH_AS(parse_byte_count(bad, "LIMIT"), doctest::Contains("LIMIT: expected a byte count"), InputError);
    CHECK(byte_size_string(999) == "999 bytes");
    CHECK(byte_size_string(512ull << 20) == "512.0 MiB");
    CHECK(byte_size_string((3ull << 30) + (1ull << 29)) == "3.5 GiB");
    // Linux always states MemAvailable; the machine running the tests has some.
    unsetenv("CLFRACTAL_MEMORY_LIMIT");
    const auto room = available_memory();
    REQUIRE(room.has_value());
    CHECK(*room > (std::uint64_t(16) << 20));
    CHECK_NOTHROW(require_memory({1, 0, "v.nrrd", "clfractal fd", "", ""}));
    setenv("CLFRACTAL_MEMORY_LIMIT", "64M", 1);
    CHECK(available_memory() == std::optional<std::uint64_t>(64ull << 20));
    CHECK_NOTHROW(require_memory({64ull << 20, 0, "v.nrrd", "clfractal fd", "", ""}));
    CHECK_NOTHROW(require_memory({80ull << 20, 16ull << 20, "v.nrrd", "clfractal fd", "", ""}));
    CHECK_THROWS_WITH_AS(require_memory({(64ull << 20) + 1, 0, "v.nrrd", "clfractal fd", "the rule", "try --stream"}),
                         "v.nrrd: clfractal fd needs about 64.0 MiB of memory (the rule), but 64.0 MiB is available "
                         "(try --stream)",
                         InputError);
    CHECK_THROWS_WITH_AS(require_memory({100ull << 20, 16ull << 20, "v\n.nrrd", "clfractal fd", "", ""}),
                         "v?.nrrd: clfractal fd needs about 100.0 MiB of memory, but 80.0 MiB is available", InputError);
    setenv("CLFRACTAL_MEMORY_LIMIT", "off", 1);
    CHECK_FALSE(available_memory().has_value());
    CHECK_NOTHROW(require_memory({~std::uint64_t(0), 0, "v.nrrd", "clfractal fd", "", ""}));
    unsetenv("CLFRACTAL_MEMORY_LIMIT");
}

}  // TEST_SUITE("volume")
