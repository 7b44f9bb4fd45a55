// avatar.usdz against the USDZ specification (Pixar, "Usdz File Format Specification"): a zip that Python's
// zipfile reads with every CRC right, nothing compressed, each file's data at a multiple of 64 bytes, the USD layer
// first; and the layer is USDA whose mesh has the glb's vertices, normals, texture coordinates and triangles.
#include "booth/usdz.h"
#include "common/atomic_output.h"
#include "fit/export/glb.h"
#include "test_paths.h"

#include <gtest/gtest.h>

#include <glm/gtc/constants.hpp>

#include <cstdio>
#include <fstream>
#include <regex>
#include <sstream>

using namespace avatarbooth;
namespace fs = std::filesystem;

namespace {

// A textured sphere of 100 mm radius (a head's size), counter-clockwise seen from outside.
Mesh sphere(int rings, int segments) {
    Mesh m;
    for (int r = 0; r <= rings; ++r) {
        const double v = static_cast<double>(r) / rings, theta = v * glm::pi<double>();
        for (int s = 0; s <= segments; ++s) {
            const double u = static_cast<double>(s) / segments, phi = u * 2.0 * glm::pi<double>();
            m.positions.emplace_back(100.0 * std::sin(theta) * std::sin(phi), 100.0 * std::cos(theta),
                                     100.0 * std::sin(theta) * std::cos(phi));
            m.uvs.emplace_back(u, v);
        }
    }
    const auto at = [&](int r, int s) { return static_cast<unsigned>(r * (segments + 1) + s); };
    for (int r = 0; r < rings; ++r)
        for (int s = 0; s < segments; ++s) {
            m.triangles.emplace_back(at(r, s), at(r + 1, s), at(r + 1, s + 1));
            m.triangles.emplace_back(at(r, s), at(r + 1, s + 1), at(r, s + 1));
        }
    return m;
}

cv::Mat texture() {
    cv::Mat t(128, 128, CV_8UC3);
    for (int y = 0; y < t.rows; ++y)
        for (int x = 0; x < t.cols; ++x) t.at<cv::Vec3b>(y, x) = cv::Vec3b(static_cast<uchar>(2 * x), 90, static_cast<uchar>(2 * y));
    return t;
}

std::string run(const std::string& cmd) {
    std::string out;
    FILE* pipe = popen((cmd + " 2>&1").c_str(), "r");
    if (!pipe) return "popen failed";
    char buffer[4096];
    while (std::fgets(buffer, sizeof buffer, pipe)) out += buffer;
    const int status = pclose(pipe);
    return out + "exit " + std::to_string(WEXITSTATUS(status));
}

// The number of elements of a USDA array attribute `declaration = [...]` (tuples count as one element).
long countElements(const std::string& usda, const std::string& declaration) {
    const std::size_t at = usda.find(declaration + " = [");
    if (at == std::string::npos) return -1;
    const std::size_t open = at + declaration.size() + 3, close = usda.find(']', open);
    const std::string body = usda.substr(open + 1, close - open - 1);
    long elements = 0;
    int depth = 0;
    bool inElement = false;
    for (const char c : body) {
        if (c == '(') ++depth;
        if (c == ')') --depth;
        if (c == ',' && depth == 0) {
            inElement = false;
            continue;
        }
        if (!std::isspace(static_cast<unsigned char>(c)) && !inElement) {
            inElement = true;
            ++elements;
        }
    }
    return elements;
}

}  // namespace

TEST(Usdz, ZipIsStoredAlignedAndReadable) {
    const fs::path dir = test::scratchDir("usdz_zip");
    const Mesh mesh = sphere(24, 48);
    writeFileAtomically(dir / "avatar.usdz", encodeUsdz(mesh, texture()));
    // Python's zipfile: CRCs (testzip), methods, the order, and each file's data offset from its local header.
    const std::string script = R"PY(
import struct, sys, zipfile
path = sys.argv[1]
z = zipfile.ZipFile(path)
assert z.testzip() is None, "bad CRC"
names = z.namelist()
assert names == ["avatar.usda", "texture.jpg"], names
raw = open(path, "rb").read()
for info in z.infolist():
    assert info.compress_type == zipfile.ZIP_STORED, (info.filename, info.compress_type)
    assert info.flag_bits & 1 == 0, "encrypted"
    sig, = struct.unpack_from("<I", raw, info.header_offset)
    assert sig == 0x04034b50
    n, m = struct.unpack_from("<HH", raw, info.header_offset + 26)
    start = info.header_offset + 30 + n + m
    assert start % 64 == 0, (info.filename, start)
    assert raw[start:start + info.file_size] == z.read(info.filename)
layer = z.read("avatar.usda").decode("ascii")
assert layer.startswith("#usda 1.0\n"), layer[:20]
assert z.read("texture.jpg")[:3] == b"\xff\xd8\xff"
print("usdz ok")
)PY";
    {
        std::ofstream(dir / "check.py") << script;
    }
    const std::string out = run("python3 " + (dir / "check.py").string() + " " + (dir / "avatar.usdz").string());
    EXPECT_NE(out.find("usdz ok\nexit 0"), std::string::npos) << out;
}

TEST(Usdz, AlignmentHoldsForEveryNameLength) {
    // The padding depends on where each header falls: names of every length mod 64, and a file whose header
    // leaves 1-3 bytes before the boundary (too few for an extra field: the padding grows by 64).
    for (std::size_t len = 1; len <= 70; ++len) {
        const std::string first(len, 'a'), data(len * 7 + 3, 'x');
        const std::string zip = storeAlignedZip({{first + ".usda", data}, {"t.jpg", data}});
        std::size_t at = 0;
        for (int file = 0; file < 2; ++file) {
            ASSERT_EQ(zip.compare(at, 4, "PK\x03\x04"), 0);
            const auto u16 = [&](std::size_t p) {
                return static_cast<std::size_t>(static_cast<unsigned char>(zip[p])) |
                       static_cast<std::size_t>(static_cast<unsigned char>(zip[p + 1])) << 8;
            };
            const std::size_t start = at + 30 + u16(at + 26) + u16(at + 28);
            ASSERT_EQ(start % 64, 0u) << "name length " << len << ", file " << file;
            ASSERT_EQ(zip.compare(start, data.size(), data), 0);
            at = start + data.size();
        }
    }
}

TEST(Usdz, LayerMeshMatchesTheGlb) {
    const fs::path dir = test::scratchDir("usdz_layer");
    const Mesh mesh = sphere(16, 32);
    writeGlb(dir / "avatar.glb", mesh, texture());
    const Mesh glb = readGlbMesh(dir / "avatar.glb");
    const std::string usda = encodeUsda(mesh, "texture.jpg");
    // The header and the prims Quick Look needs.
    EXPECT_EQ(usda.rfind("#usda 1.0\n(\n", 0), 0u);
    EXPECT_NE(usda.find("defaultPrim = \"avatar\""), std::string::npos);
    EXPECT_NE(usda.find("upAxis = \"Y\""), std::string::npos);
    EXPECT_NE(usda.find("metersPerUnit = 1\n"), std::string::npos);
    EXPECT_NE(usda.find("def Xform \"avatar\""), std::string::npos);
    EXPECT_NE(usda.find("def Mesh \"head\""), std::string::npos);
    EXPECT_NE(usda.find("uniform token info:id = \"UsdPreviewSurface\""), std::string::npos);
    EXPECT_NE(usda.find("asset inputs:file = @texture.jpg@"), std::string::npos);
    EXPECT_NE(usda.find("rel material:binding = </avatar/Materials/skin>"), std::string::npos);
    // The counts match the glb's.
    const auto n = static_cast<long>(glb.positions.size());
    EXPECT_EQ(countElements(usda, "point3f[] points"), n);
    EXPECT_EQ(countElements(usda, "normal3f[] normals"), n);
    EXPECT_EQ(countElements(usda, "texCoord2f[] primvars:st"), n);
    EXPECT_EQ(countElements(usda, "int[] faceVertexIndices"), 3 * static_cast<long>(glb.triangles.size()));
    EXPECT_EQ(countElements(usda, "int[] faceVertexCounts"), static_cast<long>(glb.triangles.size()));
    // Brackets and braces balance (a truncated or mis-nested layer does not parse).
    long braces = 0, brackets = 0, parens = 0;
    for (const char c : usda) {
        braces += c == '{' ? 1 : c == '}' ? -1 : 0;
        brackets += c == '[' ? 1 : c == ']' ? -1 : 0;
        parens += c == '(' ? 1 : c == ')' ? -1 : 0;
        ASSERT_GE(braces, 0);
    }
    EXPECT_EQ(braces, 0);
    EXPECT_EQ(brackets, 0);
    EXPECT_EQ(parens, 0);
    // The first point is the glb's first vertex in metres; st's t is flipped (USD's origin is bottom-left).
    const std::smatch first = [&] {
        std::smatch m;
        std::regex_search(usda, m, std::regex(R"(point3f\[\] points = \[\(([-0-9.e]+), ([-0-9.e]+), ([-0-9.e]+)\))"));
        return m;
    }();
    ASSERT_EQ(first.size(), 4u);
    EXPECT_NEAR(std::stod(first[1]) * 1000.0, glb.positions[0].x, 1e-3);
    EXPECT_NEAR(std::stod(first[2]) * 1000.0, glb.positions[0].y, 1e-3);
    std::smatch st;
    ASSERT_TRUE(std::regex_search(usda, st, std::regex(R"(primvars:st = \[\(([-0-9.e]+), ([-0-9.e]+)\))")));
    EXPECT_NEAR(std::stod(st[2]), 1.0 - glb.uvs[0].y, 1e-6);
}

// The avatar's parts: one Mesh and one Material each, the head's as before; a blended part's opacity is its
// texture's alpha, a masked one's with its threshold; every texture in the archive, PNG where the alpha counts.
TEST(Usdz, CarriesEveryPart) {
    const fs::path dir = test::scratchDir("usdz_parts");
    std::vector<AvatarPart> parts(3);
    parts[0].name = "head";
    parts[0].mesh = sphere(12, 24);
    parts[0].texture = texture();
    parts[1].name = "eyebrows";
    parts[1].mesh = sphere(4, 8);
    parts[1].texture = cv::Mat(16, 16, CV_8UC4, cv::Scalar(20, 30, 40, 100));
    parts[1].alpha = AlphaMode::Blend;
    parts[2].name = "eyelashes";
    parts[2].mesh = sphere(4, 8);
    parts[2].texture = cv::Mat(16, 16, CV_8UC4, cv::Scalar(0, 0, 0, 255));
    parts[2].alpha = AlphaMode::Mask;
    parts[2].alphaCutoff = 0.3;
    writeFileAtomically(dir / "avatar.usdz", encodeUsdz(parts));
    const std::string script = R"PY(
import sys, zipfile
z = zipfile.ZipFile(sys.argv[1])
assert z.testzip() is None, "bad CRC"
assert z.namelist() == ["avatar.usda", "texture.jpg", "eyebrows.png", "eyelashes.png"], z.namelist()
assert z.read("eyebrows.png")[:4] == b"\x89PNG"
layer = z.read("avatar.usda").decode("ascii")
for needle in ['def Mesh "head"', 'def Mesh "eyebrows"', 'def Mesh "eyelashes"', 'def Material "skin"',
               'def Material "eyebrows"', 'rel material:binding = </avatar/Materials/eyelashes>',
               'float inputs:opacity.connect = </avatar/Materials/eyebrows/texture.outputs:a>',
               'float inputs:opacityThreshold = 0.3', 'asset inputs:file = @eyelashes.png@']:
    assert needle in layer, needle
assert layer.count("def Mesh") == 3 and layer.count("def Material") == 3
assert layer.count("opacityThreshold") == 1
assert layer.count("{") == layer.count("}")
print("parts ok")
)PY";
    {
        std::ofstream(dir / "check.py") << script;
    }
    const std::string out = run("python3 " + (dir / "check.py").string() + " " + (dir / "avatar.usdz").string());
    EXPECT_NE(out.find("parts ok\nexit 0"), std::string::npos) << out;
}
