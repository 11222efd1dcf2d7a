/// @file UsdText.h
/// @brief USD text (`.usda`) parsed into what the strand reader needs (UsdFile.cc): the prim tree
/// with each prim's transform properties, and every `def BasisCurves` prim's properties, values
/// flattened. Values and prims nest at most kMaxNesting deep (the parser recurses once a level).
#pragma once

#include <cstddef>
#include <limits>
#include <map>
#include <string>
#include <vector>

namespace vdbhair {
namespace usd {

/// Values and prims nest at most this deep: the parser recurses once per level, so a file
/// cannot run it out of stack (real files nest values 2-3 deep and prims a few tens).
constexpr int kMaxNesting = 128;

/// A value, flattened: every number in order, every string or word, how many top-level elements.
struct FlatValue
{
    std::vector<double> numbers;
    std::vector<std::string> words;
    std::size_t elements = 0;  ///< top-level array elements (1 for a scalar)
    bool array = false;
    std::size_t line = 0;
};

struct Property
{
    FlatValue value;
    std::string interpolation;
    bool hasValue = false;
    bool sampled = false;  ///< the value is the first of its time samples
};

constexpr std::size_t kNoParent = std::numeric_limits<std::size_t>::max();

/// A prim of the tree, for its transform: its parent and its `xformOpOrder` and `xformOp:*`.
struct PrimNode
{
    std::size_t parent = kNoParent;
    std::string name;
    std::size_t line = 0;
    std::map<std::string, Property> xformProps;
};

struct CurvesPrim
{
    std::string name;
    std::size_t line = 0;
    std::size_t node = 0;  ///< its PrimNode
    std::map<std::string, Property> props;
};

struct UsdDocument
{
    std::vector<PrimNode> nodes;
    std::vector<CurvesPrim> curves;
    std::string upAxis;
    double metersPerUnit = 0.0;  ///< 0: not in the stage's metadata
    std::size_t timeSampled = 0;  ///< properties read at their first time sample
};

/// @brief Parse USD text (starting with `#usda 1.0`; a binary crate is refused with
/// UnsupportedError, anything else with FormatError naming @a where and the line).
UsdDocument parseUsda(const std::vector<char>& bytes, const std::string& where);

} // namespace usd
} // namespace vdbhair
