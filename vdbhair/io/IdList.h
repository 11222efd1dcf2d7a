/// @file IdList.h
/// @brief A list of integer ids, or of numbers, in a text file (one per guide or root: group ids for
/// `interpolate --guide-groups` and `--root-groups`): integers separated by white space or commas,
/// `#` starting a comment to the end of the line. What spreadsheets, NumPy's savetxt and a shell
/// loop all write.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace vdbhair {

/// @brief The ids in @a path, in order.
/// @param expected the count there must be (0: any)
/// @param what what the ids belong to, for messages ("guides")
/// @throw IoError (unreadable), FormatError naming the line and the text that is not a 32-bit
/// integer, ValueError naming the count found and the count expected.
std::vector<std::int32_t> readIdList(const std::string& path, std::size_t expected, const std::string& what);

/// @brief As readIdList(), for finite real numbers (one value per root: `interpolate --density`,
/// `--length`).
/// @throw IoError, FormatError naming the line and the text that is not a finite number,
/// ValueError naming the count found and the count expected.
std::vector<double> readValueList(const std::string& path, std::size_t expected, const std::string& what);

} // namespace vdbhair
