/// @file ImageModule.h
/// @brief The C interface of vdbhair's image module (libvdbhair_image.so), the only part of
/// vdbhair linked to OpenImageIO. OpenImageIO brings about 250 shared libraries (FFmpeg, OpenCV,
/// GDAL, GStreamer, ...) whose loading costs every process close to a second before main(); so
/// the library loads the module with dlopen() the first time an image is written or text drawn
/// (Image.cc), and every other command starts in a few hundredths of a second.
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
    /// Draw @a text into @a rgb (width·height·3 floats) with its left baseline at (x, y).
    void (*drawText)(float* rgb, int width, int height, int x, int y, const char* text, int size, const char* font,
                     const float* color);
};

/// The module's one exported symbol.
const VdbhairImageModule* vdbhair_image_module();
}

constexpr int kVdbhairImageModuleVersion = 1;
