// Modifier basis: applying it, and its file.
#include "fit/head/modifier_basis.h"

#include "common/atomic_output.h"
#include "common/error.h"

#include <cstring>
#include <fstream>
#include <iterator>

namespace avatarbooth {
namespace {

constexpr char kMagic[8] = {'A', 'B', 'M', 'O', 'D', 'B', 'A', 'S'};
constexpr std::uint32_t kVersion = 1;

void putU32(std::string& out, std::uint32_t v) {
    for (int i = 0; i < 4; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}
void putString(std::string& out, const std::string& s) {
    putU32(out, static_cast<std::uint32_t>(s.size()));
    out += s;
}
void putFloat(std::string& out, float f) {
    std::uint32_t u = 0;
    std::memcpy(&u, &f, 4);
    putU32(out, u);
}

class Reader {
public:
    Reader(const std::string& bytes, std::string where) : bytes_(bytes), where_(std::move(where)) {}
    std::uint32_t u32() {
        need(4);
        std::uint32_t v = 0;
        for (int i = 0; i < 4; ++i) v |= static_cast<std::uint32_t>(static_cast<unsigned char>(bytes_[at_ + i])) << (8 * i);
        at_ += 4;
        return v;
    }
    float f32() {
        const std::uint32_t u = u32();
        float f = 0;
        std::memcpy(&f, &u, 4);
        return f;
    }
    std::string string(std::size_t maxLength) {
        const std::uint32_t n = u32();
        if (n > maxLength) fail("a name longer than " + std::to_string(maxLength) + " bytes");
        need(n);
        std::string s = bytes_.substr(at_, n);
        at_ += n;
        return s;
    }
    void need(std::size_t n) const {
        if (bytes_.size() - at_ < n) fail("it ends early (truncated)");
    }
    bool atEnd() const { return at_ == bytes_.size(); }
    [[noreturn]] void fail(const std::string& why) const {
        throw BoothError(ErrorKind::BadConfig, where_, "is not a valid modifier basis: " + why);
    }

private:
    const std::string& bytes_;
    std::string where_;
    std::size_t at_ = 0;
};

}  // namespace

std::vector<glm::dvec3> ModifierBasis::apply(const std::vector<glm::dvec3>& base, const std::vector<double>& weights) const {
    if (base.size() != vertexCount || weights.size() != modifiers.size())
        throw BoothError(ErrorKind::Internal, "modifier basis", "applied to a mesh or weights of the wrong size");
    std::vector<glm::dvec3> out(base);
    for (std::size_t k = 0; k < modifiers.size(); ++k) {
        const double w = weights[k];
        if (w == 0.0) continue;
        const Modifier& m = modifiers[k];
        for (std::size_t i = 0; i < m.vertices.size(); ++i) out[m.vertices[i]] += w * glm::dvec3(m.offsets[i]);
    }
    return out;
}

std::string mirroredModifierName(const std::string& name) {
    const auto slash = name.find('/');
    if (slash == std::string::npos || slash + 2 >= name.size() || name[slash + 2] != '-') return name;
    std::string m = name;
    if (name[slash + 1] == 'r') m[slash + 1] = 'l';
    else if (name[slash + 1] == 'l') m[slash + 1] = 'r';
    return m;
}

std::size_t ModifierBasis::find(const std::string& name) const {
    for (std::size_t k = 0; k < modifiers.size(); ++k)
        if (modifiers[k].name == name) return k;
    return modifiers.size();
}

void saveModifierBasis(const ModifierBasis& basis, const std::filesystem::path& file) {
    std::string out(kMagic, sizeof kMagic);
    putU32(out, kVersion);
    putU32(out, static_cast<std::uint32_t>(basis.vertexCount));
    putU32(out, static_cast<std::uint32_t>(basis.modifiers.size()));
    for (const Modifier& m : basis.modifiers) {
        putString(out, m.name);
        putString(out, m.group);
        putU32(out, static_cast<std::uint32_t>(m.vertices.size()));
        for (std::size_t i = 0; i < m.vertices.size(); ++i) {
            putU32(out, m.vertices[i]);
            for (int c = 0; c < 3; ++c) putFloat(out, m.offsets[i][c]);
        }
    }
    writeFileAtomically(file, out);
}

ModifierBasis loadModifierBasis(const std::filesystem::path& file, std::size_t expectedVertexCount) {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw BoothError(ErrorKind::BadConfig, file.string(), "the modifier basis cannot be opened");
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    Reader body(bytes, file.string());
    body.need(sizeof kMagic);
    if (std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0) body.fail("no ABMODBAS header");
    for (int i = 0; i < 2; ++i) body.u32();  // past the magic
    if (const std::uint32_t v = body.u32(); v != kVersion)
        body.fail("format version " + std::to_string(v) + ", this build reads " + std::to_string(kVersion));
    ModifierBasis basis;
    basis.vertexCount = body.u32();
    if (basis.vertexCount != expectedVertexCount)
        body.fail("made for a head of " + std::to_string(basis.vertexCount) + " vertices, the mesh has " +
                  std::to_string(expectedVertexCount));
    const std::uint32_t count = body.u32();
    if (count > 100000) body.fail(std::to_string(count) + " modifiers");
    basis.modifiers.resize(count);
    for (Modifier& m : basis.modifiers) {
        m.name = body.string(256);
        m.group = body.string(256);
        const std::uint32_t n = body.u32();
        if (n > basis.vertexCount) body.fail("modifier '" + m.name + "' moves more vertices than the head has");
        body.need(static_cast<std::size_t>(n) * 16);
        m.vertices.resize(n);
        m.offsets.resize(n);
        for (std::uint32_t i = 0; i < n; ++i) {
            m.vertices[i] = body.u32();
            if (m.vertices[i] >= basis.vertexCount) body.fail("modifier '" + m.name + "' names a vertex past the mesh");
            for (int c = 0; c < 3; ++c) m.offsets[i][c] = body.f32();
        }
    }
    if (!body.atEnd()) body.fail("bytes after the last modifier");
    return basis;
}

}  // namespace avatarbooth
