/// @file PlyHeader.h
/// @brief The header of a PLY file (encoding, elements and their properties), parsed for the
/// PLY readers of PlyFile.cc: strands, meshes, oriented points and vertex values.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace vdbhair {
namespace ply {

enum class PlyType { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64, Invalid };

/// The type a header names ("float", "uint8", ...; the PLY names and their sized aliases), or
/// PlyType::Invalid.
PlyType plyType(std::string_view s);

/// The bytes of a binary value of type @a t (0 for PlyType::Invalid).
std::size_t plySize(PlyType t);

struct Property
{
    std::string name;
    PlyType type = PlyType::Invalid;
    bool isList = false;
    PlyType countType = PlyType::Invalid;
};

struct Element
{
    std::string name;
    std::uint64_t count = 0;
    std::vector<Property> props;
    std::size_t line = 0;  ///< the header line that declares it, for messages
};

/// The header of a PLY file: encoding, elements, and where the body starts.
struct PlyHeader
{
    bool binary = false;
    std::vector<Element> elements;
    std::size_t bodyOffset = 0, bodyLine = 0;
};

/// @brief Parse the header at the start of the @a size bytes at @a data.
/// @param where message prefix, e.g. "readPly(a.ply)"
/// @throw FormatError naming the line and the rule broken; UnsupportedError for big-endian data.
PlyHeader parsePlyHeader(const char* data, std::size_t size, const std::string& where);

/// Index of @a e's property @a name (a scalar, or a list with @a list), or -1 (also when @a e is
/// null).
int findProperty(const Element* e, const char* name, bool list = false);

/// The (last) element named `vertex` of @a hdr.
/// @throw FormatError when there is none.
const Element& vertexElement(const PlyHeader& hdr, const std::string& where);

} // namespace ply
} // namespace vdbhair
