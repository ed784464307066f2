// ValueType <-> teem's NRRD types, through the NRRD type names of the type table
// (include/clfractal/volume.hpp).
#pragma once
#include <teem/nrrd.h>

#include <optional>

#include "clfractal/volume.hpp"
#include "io/formats.hpp"

namespace clfractal {

/// teem's nrrdType value of t.
inline int nrrd_type_of(ValueType t) { return airEnumVal(nrrdType, nrrd_type_name(t)); }

/// The ValueType of a teem nrrdType value; nullopt for types clfractal does not read
/// (64-bit integers, block).
inline std::optional<ValueType> value_type_of_nrrd(int nrrd_type) {
    for (ValueType t : all_value_types)
        if (nrrd_type_of(t) == nrrd_type) return t;
    return std::nullopt;
}

namespace io {
/// Where the grid of a NRRD header lies: the spacing of each axis (its scalar spacing or the
/// length of its space direction) and, for an RAS or LPS space, the LPS origin and unit axes.
/// The one reading, for whole volumes and SliceReader alike.
Geometry nrrd_geometry(const Nrrd* n);
}  // namespace io

}  // namespace clfractal
