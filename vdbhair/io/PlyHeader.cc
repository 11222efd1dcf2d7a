// The PLY header (PlyHeader.h): the lines before end_header, checked keyword by keyword.
#include "PlyHeader.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/TextScanner.h>

namespace vdbhair {
namespace ply {

PlyType plyType(std::string_view s)
{
    if (s == "char" || s == "int8") return PlyType::Int8;
    if (s == "uchar" || s == "uint8") return PlyType::UInt8;
    if (s == "short" || s == "int16") return PlyType::Int16;
    if (s == "ushort" || s == "uint16") return PlyType::UInt16;
    if (s == "int" || s == "int32") return PlyType::Int32;
    if (s == "uint" || s == "uint32") return PlyType::UInt32;
    if (s == "float" || s == "float32") return PlyType::Float32;
    if (s == "double" || s == "float64") return PlyType::Float64;
    return PlyType::Invalid;
}

std::size_t plySize(PlyType t)
{
    switch (t) {
    case PlyType::Int8: case PlyType::UInt8: return 1;
    case PlyType::Int16: case PlyType::UInt16: return 2;
    case PlyType::Int32: case PlyType::UInt32: case PlyType::Float32: return 4;
    case PlyType::Float64: return 8;
    default: return 0;
    }
}

PlyHeader parsePlyHeader(const char* data, std::size_t size, const std::string& where)
{
    TextScanner header(data, size, where);
    std::vector<std::string_view> tok;
    if (!header.nextLine(tok) || tok.size() != 1 || tok[0] != "ply") header.fail("not a PLY file: the first line must be 'ply'");
    bool binary = false, sawFormat = false;
    std::vector<Element> elements;
    bool ended = false;
    while (header.nextLine(tok)) {
        if (tok.empty()) continue;
        if (tok[0] == "format") {
            if (tok.size() < 3) header.fail("'format' needs an encoding and a version");
            if (tok[1] == "ascii") binary = false;
            else if (tok[1] == "binary_little_endian") binary = true;
            else if (tok[1] == "binary_big_endian") throw UnsupportedError(where + ": line " + std::to_string(header.line()) + ": binary_big_endian PLY is not supported (ascii and binary_little_endian are)");
            else header.fail("unknown format '" + std::string(tok[1]) + "'");
            sawFormat = true;
        } else if (tok[0] == "element") {
            if (tok.size() != 3) header.fail("'element' needs a name and a count");
            const std::int64_t count = header.toInt(tok[2], "element count");
            if (count < 0) header.fail("element '" + std::string(tok[1]) + "' has a negative count " + std::to_string(count));
            elements.push_back({std::string(tok[1]), std::uint64_t(count), {}, header.line()});
        } else if (tok[0] == "property") {
            if (elements.empty()) header.fail("'property' before any 'element'");
            Property p;
            if (tok.size() == 5 && tok[1] == "list") {
                p.isList = true;
                p.countType = plyType(tok[2]);
                p.type = plyType(tok[3]);
                p.name = std::string(tok[4]);
                if (p.countType == PlyType::Invalid || p.countType == PlyType::Float32 || p.countType == PlyType::Float64) {
                    header.fail("list count type '" + std::string(tok[2]) + "' must be an integer type");
                }
            } else if (tok.size() == 3) {
                p.type = plyType(tok[1]);
                p.name = std::string(tok[2]);
            } else {
                header.fail("'property' needs a type and a name");
            }
            if (p.type == PlyType::Invalid) header.fail("unknown property type in '" + std::string(tok[1]) + "'");
            elements.back().props.push_back(p);
        } else if (tok[0] == "end_header") {
            ended = true;
            break;
        } else if (tok[0] == "comment" || tok[0] == "obj_info") {
            continue;
        } else {
            header.fail("unexpected header keyword '" + std::string(tok[0]) + "'");
        }
    }
    if (!ended) header.fail("the header has no 'end_header'");
    if (!sawFormat) header.fail("the header has no 'format' line");

    return PlyHeader{binary, std::move(elements), header.offset(), header.line()};
}

int findProperty(const Element* e, const char* name, bool list)
{
    if (!e) return -1;
    for (std::size_t i = 0; i < e->props.size(); ++i) {
        if (e->props[i].name == name && e->props[i].isList == list) return int(i);
    }
    return -1;
}

const Element& vertexElement(const PlyHeader& hdr, const std::string& where)
{
    const Element* vertexEl = nullptr;
    for (const Element& e : hdr.elements) {
        if (e.name == "vertex") vertexEl = &e;
    }
    if (!vertexEl) throw FormatError(where + ": the header has no 'vertex' element");
    return *vertexEl;
}

} // namespace ply
} // namespace vdbhair
