/// @file JsonFile.h
/// @brief JSON documents read without recursion on their depth: a first pass with nlohmann's
/// (iterative) SAX parser refuses nesting beyond a cap and numbers beyond a double by key path
/// ("guides[3].root[1]") before any json value is built, since building, copying and destroying
/// one recurses on its depth (a document nested 200,000 deep overflowed the stack).
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace vdbhair {

/// @brief Parse @a bytes. @param where the message prefix (the file name); @param noun what the
/// document is, for the message ("a scene nests at most 64 levels").
/// @throw FormatError naming @a where, the key path and the rule (invalid JSON with its line and
/// column, nesting beyond @a maxDepth, a number beyond a double).
nlohmann::json parseJsonChecked(const std::vector<char>& bytes, const std::string& where, std::size_t maxDepth,
                                const std::string& noun);

/// @brief Read and parse the file @a path (parseJsonChecked(); IoError when it cannot be read).
nlohmann::json readJsonFile(const std::string& path, std::size_t maxDepth, const std::string& noun);

} // namespace vdbhair
