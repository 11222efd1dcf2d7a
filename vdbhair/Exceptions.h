/// @file Exceptions.h
/// @brief Typed errors. Library code throws and never exits (OpenVDB's rule); the command
/// prints `vdbhair <verb>: <message>` and exits non-zero.
///
/// Messages say where (the function and file), what, the value received and the rule broken:
/// `readHair(bangs.hair): at byte 128: strand 12 declares 70000 points but only 1200 remain`.
#pragma once

#include <stdexcept>
#include <string>

namespace vdbhair {

/// Base of every vdbhair error.
class Error : public std::runtime_error
{
public:
    explicit Error(const std::string& msg) : std::runtime_error(msg) {}
};

/// A file could not be opened, read, written or renamed (the operating system's reason follows).
class IoError : public Error { public: using Error::Error; };

/// A file's content breaks its format: wrong magic, truncated array, impossible count, NaN.
class FormatError : public Error { public: using Error::Error; };

/// A file's format or version is recognised but not supported.
class UnsupportedError : public Error { public: using Error::Error; };

/// An argument is out of its valid range (a voxel size of zero, an unknown view name).
class ValueError : public Error { public: using Error::Error; };

/// A named item is missing: a grid not in a file, an unknown key.
class LookupError : public Error { public: using Error::Error; };

/// An item has the wrong type: a float grid where a vector grid is needed.
class TypeError : public Error { public: using Error::Error; };

/// Work would exceed a resource cap (memory, voxel count); the message says the estimate and the cap.
class LimitError : public Error { public: using Error::Error; };

/// Work was stopped by an interrupter (Ctrl-C); nothing was written.
class InterruptedError : public Error { public: using Error::Error; };

} // namespace vdbhair
