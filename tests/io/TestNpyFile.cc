#include "../TestUtil.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/NpyFile.h>

#include <cstring>

using namespace vdbhair;

TEST_CASE("npyHeader: NumPy 1.0 header, data aligned to 64 bytes", "[io]")
{
    const std::string h = npyHeader({96, 128, 128, 4});
    REQUIRE(h.size() % 64 == 0);
    CHECK(h.compare(0, 8, std::string("\x93NUMPY\x01\x00", 8)) == 0);
    const std::size_t len = std::size_t(static_cast<unsigned char>(h[8])) | (std::size_t(static_cast<unsigned char>(h[9])) << 8);
    CHECK(len + 10 == h.size());
    CHECK(h.find("{'descr': '<f4', 'fortran_order': False, 'shape': (96, 128, 128, 4), }") == 10);
    CHECK(h.back() == '\n');
    CHECK(npyHeader({5}).find("'shape': (5, )") != std::string::npos);  // a one-element tuple keeps its comma
}

TEST_CASE("writeNpy: header then the floats in C order", "[io]")
{
    const std::string path = test::tempPath("writeNpy.npy");
    const std::vector<float> data{1.0f, -2.5f, 3.0f, 4.0f, 5.0f, 6.0f};
    writeNpy(path, {2, 3}, data.data());
    const std::string bytes = test::readBytes(path);
    const std::string header = npyHeader({2, 3});
    REQUIRE(bytes.size() == header.size() + 6 * sizeof(float));
    float back[6];
    std::memcpy(back, bytes.data() + header.size(), sizeof back);
    for (int i = 0; i < 6; ++i) CHECK(back[i] == data[std::size_t(i)]);
    CHECK_THROWS_AS(writeNpy(path, {}, data.data()), ValueError);
    std::remove(path.c_str());
}
