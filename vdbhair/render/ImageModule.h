/// @file ImageModule.h
/// @brief The C interface of vdbhair's image module (libvdbhair_image.so), the only part of
/// vdbhair linked to OpenImageIO. OpenImageIO brings about 250 shared libraries (FFmpeg, OpenCV,
/// GDAL, GStreamer, ...) whose loading costs a process about half a second; so the library writes
/// PNG itself (libpng) and draws text itself (FreeType), and loads the module with dlopen() only
/// the first time another format is asked for (Image.cc): EXR, JPEG, TIFF, ...
#pragma once

#include <cstddef>

extern "C" {

struct VdbhairImageModule
{
    int version;  ///< kVdbhairImageModuleVersion of the module's build
    /// Whether OpenImageIO has a writer for @a path's extension.
    int (*canWrite)(const char* path);
    /// Write @a rgb (width·height·3 floats, top row first) to @a path: 8-bit when @a asFloat is 0
    /// (the values are already encoded), float otherwise. 0 on success, else a message in @a err.
    int (*write)(const char* path, int width, int height, int asFloat, const float* rgb, char* err, std::size_t errSize);
};

/// The module's one exported symbol.
const VdbhairImageModule* vdbhair_image_module();
}

constexpr int kVdbhairImageModuleVersion = 2;
