// dlib's shape predictor with 16-bit leaves: read tree by tree from dlib's file (or mapped from our cache of it),
// walked as dlib walks it.
#include "fit/face/quantized_shape_predictor.h"

#include "common/error.h"
#include "fit/face/model_cache.h"

#include <dlib/image_processing/shape_predictor.h>
#include <dlib/opencv/cv_image.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>

namespace avatarbooth {

// One tree's splits use the features of its cascade by index; a cascade of dlib's model samples 500 pixels, so
// 16 bits hold the index (checked at load).
struct QuantizedSplit {
    std::uint16_t idx1 = 0, idx2 = 0;
    float thresh = 0.0f;
};

struct QuantizedShapePredictor::Model {
    dlib::matrix<float, 0, 1> initialShape;  // the mean shape, in the face box's unit square (x0 y0 x1 y1 ...)
    struct Cascade {
        std::vector<unsigned long> anchorIdx;           // per feature pixel: the shape point it hangs from
        std::vector<dlib::vector<float, 2>> deltas;     // and its offset from that point, in the mean shape
        std::size_t firstTree = 0, trees = 0;
    };
    std::vector<Cascade> cascades;
    // Per tree: where its splits and leaves start; splits then leaves in the arrays below (a full binary tree:
    // leaves = splits + 1, a power of two).
    struct Tree {
        std::uint32_t firstSplit = 0, splits = 0, firstLeaf = 0;
    };
    // The trees' arrays, views of `converted` or of the mapped cache file `mapped`.
    std::span<const Tree> trees;
    std::span<const QuantizedSplit> splits;
    // Leaf l's vector is scales[l] * leaves[l * dims .. (l + 1) * dims): each leaf scaled to its own largest
    // value, so its rounding error is at most 1/65534 of that. Summed over the trees that moves the shape by about
    // 1e-5 of the face box, which now and then rounds a point to the next pixel or sends a later tree down the
    // other branch (tests/data: mean 0.09 px from dlib's, at most 2 px).
    std::span<const float> scales;
    std::span<const std::int16_t> leaves;
    std::size_t dims = 0;  // 2 x parts

    struct Arrays {
        std::vector<Tree> trees;
        std::vector<QuantizedSplit> splits;
        std::vector<float> scales;
        std::vector<std::int16_t> leaves;
    } converted;
    std::unique_ptr<const CacheFile> mapped;
};

namespace {

[[noreturn]] void notAModel(const std::filesystem::path& file, const std::string& why) {
    throw BoothError(ErrorKind::BadConfig, file.string(), "is not a dlib shape predictor: " + why);
}

// Appends one of dlib's trees to the model, its leaves rounded to 16 bits.
void addTree(QuantizedShapePredictor::Model& m, const dlib::impl::regression_tree& tree,
             const std::filesystem::path& file) {
    QuantizedShapePredictor::Model::Arrays& a = m.converted;
    const std::size_t leafCount = tree.leaf_values.size();
    if (leafCount == 0 || (leafCount & (leafCount - 1)) != 0 || tree.splits.size() + 1 != leafCount)
        notAModel(file, "a tree has " + std::to_string(tree.splits.size()) + " splits and " +
                            std::to_string(leafCount) + " leaves (a full binary tree is expected)");
    if (a.splits.size() + tree.splits.size() > std::numeric_limits<std::uint32_t>::max() ||
        a.scales.size() + leafCount > std::numeric_limits<std::uint32_t>::max())
        notAModel(file, "too many trees");
    QuantizedShapePredictor::Model::Tree t;
    t.firstSplit = static_cast<std::uint32_t>(a.splits.size());
    t.splits = static_cast<std::uint32_t>(tree.splits.size());
    t.firstLeaf = static_cast<std::uint32_t>(a.scales.size());
    for (const auto& s : tree.splits) {
        if (s.idx1 > std::numeric_limits<std::uint16_t>::max() || s.idx2 > std::numeric_limits<std::uint16_t>::max())
            notAModel(file, "a split uses feature " + std::to_string(std::max(s.idx1, s.idx2)) +
                                " (at most 65535 features per cascade are supported)");
        a.splits.push_back({static_cast<std::uint16_t>(s.idx1), static_cast<std::uint16_t>(s.idx2), s.thresh});
    }
    for (const auto& leaf : tree.leaf_values) {
        if (static_cast<std::size_t>(leaf.size()) != m.dims)
            notAModel(file, "a leaf holds " + std::to_string(leaf.size()) + " values, the shape " +
                                std::to_string(m.dims));
        float largest = 0.0f;
        for (long k = 0; k < leaf.size(); ++k) {
            if (!std::isfinite(leaf(k))) notAModel(file, "a leaf holds a value that is not a number");
            largest = std::max(largest, std::abs(leaf(k)));
        }
        const float scale = largest / 32767.0f;
        a.scales.push_back(scale);
        for (long k = 0; k < leaf.size(); ++k)
            a.leaves.push_back(scale > 0.0f ? static_cast<std::int16_t>(std::lround(leaf(k) / scale)) : 0);
    }
    a.trees.push_back(t);
}

}  // namespace

QuantizedShapePredictor::QuantizedShapePredictor(const std::filesystem::path& file) {
    // A plain stream, read front to back: the file may be a pipe (dlib's own proxy_deserialize seeks).
    std::ifstream in(file, std::ios::binary);
    if (!in) throw BoothError(ErrorKind::BadConfig, file.string(), std::string("cannot be read: ") + std::strerror(errno));
    auto m = std::make_unique<Model>();
    Model::Arrays& a = m->converted;
    try {
        // dlib's format (shape_predictor.h, serialize): version 1, the initial shape, the forests (a vector of
        // cascades, each a vector of trees), then per cascade the feature pixels' anchors and offsets.
        int version = 0;
        dlib::deserialize(version, in);
        if (version != 1) notAModel(file, "version " + std::to_string(version) + " (1 expected)");
        dlib::deserialize(m->initialShape, in);
        m->dims = static_cast<std::size_t>(m->initialShape.size());
        if (m->dims == 0 || m->dims % 2 != 0)
            notAModel(file, "its mean shape has " + std::to_string(m->dims) + " coordinates");
        unsigned long cascades = 0;
        dlib::deserialize(cascades, in);
        if (cascades == 0 || cascades > 1000) notAModel(file, std::to_string(cascades) + " cascades");
        m->cascades.resize(cascades);
        dlib::impl::regression_tree tree;  // one at a time: its 16 float leaves are reused from tree to tree
        for (auto& cascade : m->cascades) {
            unsigned long trees = 0;
            dlib::deserialize(trees, in);
            if (trees > 100000) notAModel(file, std::to_string(trees) + " trees in a cascade");
            cascade.firstTree = a.trees.size();
            cascade.trees = trees;
            for (unsigned long t = 0; t < trees; ++t) {
                using dlib::deserialize;  // the tree's own (a friend, found by argument-dependent lookup)
                deserialize(tree, in);
                if (a.trees.empty()) {  // the first tree tells the model's size: one block for all the leaves
                    const std::size_t expected = cascades * trees * tree.leaf_values.size();
                    a.trees.reserve(cascades * trees);
                    a.splits.reserve(expected);
                    a.scales.reserve(expected);
                    a.leaves.reserve(expected * m->dims);
                }
                addTree(*m, tree, file);
            }
        }
        std::vector<std::vector<unsigned long>> anchors;
        std::vector<std::vector<dlib::vector<float, 2>>> deltas;
        dlib::deserialize(anchors, in);
        dlib::deserialize(deltas, in);
        if (anchors.size() != cascades || deltas.size() != cascades)
            notAModel(file, "feature pixels for " + std::to_string(anchors.size()) + " cascades, " +
                                std::to_string(cascades) + " expected");
        for (std::size_t c = 0; c < cascades; ++c) {
            auto& cascade = m->cascades[c];
            if (anchors[c].size() != deltas[c].size())
                notAModel(file, "cascade " + std::to_string(c) + " has anchors and offsets of different counts");
            for (const unsigned long anchor : anchors[c])
                if (anchor >= m->dims / 2)
                    notAModel(file, "a feature pixel hangs from a shape point that does not exist");
            for (std::size_t t = cascade.firstTree; t < cascade.firstTree + cascade.trees; ++t)
                for (std::uint32_t s = 0; s < a.trees[t].splits; ++s) {
                    const QuantizedSplit& split = a.splits[a.trees[t].firstSplit + s];
                    if (split.idx1 >= anchors[c].size() || split.idx2 >= anchors[c].size())
                        notAModel(file, "a split in cascade " + std::to_string(c) + " uses a feature pixel it lacks");
                }
            cascade.anchorIdx = std::move(anchors[c]);
            cascade.deltas = std::move(deltas[c]);
        }
    } catch (const dlib::serialization_error& e) {
        notAModel(file, e.what());
    }
    a.trees.shrink_to_fit();
    m->trees = a.trees;
    m->splits = a.splits;
    m->scales = a.scales;
    m->leaves = a.leaves;
    model_ = std::move(m);
}

QuantizedShapePredictor::QuantizedShapePredictor(std::unique_ptr<const Model> model, std::filesystem::path cacheRead)
    : model_(std::move(model)), cacheRead_(std::move(cacheRead)) {}

QuantizedShapePredictor::~QuantizedShapePredictor() = default;

namespace {

// The cache's layout, version 1: CacheCounts, then the mean shape, the cascades (CacheCascade), the feature
// pixels' anchors (uint32) and offsets (x, y), then the trees' four arrays as the model holds them. The version
// changes with the layout and with the rounding of the leaves (a cache holds their rounded values).
constexpr CacheKind kCacheKind{"shape-predictor", 1};

struct CacheCounts {
    std::uint64_t dims, cascades, trees, splits, leaves, features;
};
struct CacheCascade {
    std::uint64_t firstTree, trees, firstFeature, features;
};
static_assert(std::is_trivially_copyable_v<QuantizedShapePredictor::Model::Tree> &&
              std::is_trivially_copyable_v<QuantizedSplit> && sizeof(QuantizedShapePredictor::Model::Tree) == 12 &&
              sizeof(QuantizedSplit) == 8);

template <typename T>
std::string_view bytesOf(std::span<const T> items) {
    return {reinterpret_cast<const char*>(items.data()), items.size_bytes()};
}

void writeCache(const QuantizedShapePredictor::Model& m, const std::filesystem::path& file, std::string_view stamp) {
    CacheCounts counts{m.dims, m.cascades.size(), m.trees.size(), m.splits.size(), m.scales.size(), 0};
    std::vector<CacheCascade> cascades;
    std::vector<std::uint32_t> anchors;
    std::vector<float> deltas;
    for (const auto& c : m.cascades) {
        cascades.push_back({c.firstTree, c.trees, anchors.size(), c.anchorIdx.size()});
        for (const unsigned long anchor : c.anchorIdx) anchors.push_back(static_cast<std::uint32_t>(anchor));
        for (const auto& d : c.deltas) deltas.insert(deltas.end(), {d.x(), d.y()});
    }
    counts.features = anchors.size();
    const std::string_view pieces[] = {
        bytesOf(std::span<const CacheCounts>(&counts, 1)), bytesOf(std::span<const float>(&m.initialShape(0), m.dims)),
        bytesOf(std::span<const CacheCascade>(cascades)),   bytesOf(std::span<const std::uint32_t>(anchors)),
        bytesOf(std::span<const float>(deltas)),            bytesOf(m.trees),
        bytesOf(m.splits),                                  bytesOf(m.scales),
        bytesOf(m.leaves)};
    CacheFile::write(file, kCacheKind, stamp, pieces);
}

// The payload's arrays in order, each at a multiple of CacheFile::kAlignment bytes (the payload's start is too).
class PayloadReader {
public:
    explicit PayloadReader(std::span<const std::byte> payload) : payload_(payload) {}
    template <typename T>
    bool next(std::uint64_t count, std::span<const T>& out) {
        if (count > (payload_.size() - at_) / sizeof(T)) return false;
        out = std::span<const T>(reinterpret_cast<const T*>(payload_.data() + at_), static_cast<std::size_t>(count));
        constexpr std::size_t a = CacheFile::kAlignment;
        at_ = std::min(payload_.size(), at_ + (out.size_bytes() + a - 1) / a * a);
        return true;
    }
    bool atEnd() const { return at_ == payload_.size(); }

private:
    std::span<const std::byte> payload_;
    std::size_t at_ = 0;
};

// The mean shape and the offsets are in units of the face box, and a leaf's scale is its largest value / 32767: a
// value beyond `limit` is damage (and could overflow the shape's rounding to pixels).
bool allWithin(std::span<const float> values, float limit) {
    return std::all_of(values.begin(), values.end(), [limit](float v) { return std::abs(v) <= limit; });
}

// The model whose trees are the cache's mapped arrays, every index in them checked (the walk trusts them); null
// with the reason in `why` when it holds no whole, consistent model.
std::unique_ptr<const QuantizedShapePredictor::Model> modelFromCache(std::unique_ptr<const CacheFile> cache,
                                                                     std::string& why) {
    using Model = QuantizedShapePredictor::Model;
    const auto bad = [&](const std::string& what) {
        why = "does not hold a whole model (" + what + ")";
        return nullptr;
    };
    PayloadReader in(cache->payload());
    std::span<const CacheCounts> countsSpan;
    if (!in.next(1, countsSpan)) return bad("no counts");
    const CacheCounts n = countsSpan[0];
    constexpr std::uint64_t k32 = std::numeric_limits<std::uint32_t>::max();
    if (n.dims == 0 || n.dims % 2 != 0 || n.dims > 100000 || n.cascades == 0 || n.cascades > 1000 || n.trees > k32 ||
        n.splits > k32 || n.leaves > k32 || n.features > k32)
        return bad("counts out of range");
    std::span<const float> shape, deltas, scales;
    std::span<const CacheCascade> cascades;
    std::span<const std::uint32_t> anchors;
    std::span<const Model::Tree> trees;
    std::span<const QuantizedSplit> splits;
    std::span<const std::int16_t> leaves;
    if (!in.next(n.dims, shape) || !in.next(n.cascades, cascades) || !in.next(n.features, anchors) ||
        !in.next(2 * n.features, deltas) || !in.next(n.trees, trees) || !in.next(n.splits, splits) ||
        !in.next(n.leaves, scales) || !in.next(n.leaves * n.dims, leaves) || !in.atEnd())
        return bad("its arrays do not fill it");
    if (!allWithin(shape, 100.0f) || !allWithin(deltas, 100.0f) || !allWithin(scales, 1.0f))
        return bad("a value out of all proportion");

    auto m = std::make_unique<Model>();
    m->dims = static_cast<std::size_t>(n.dims);
    m->initialShape.set_size(static_cast<long>(n.dims));
    std::copy(shape.begin(), shape.end(), &m->initialShape(0));
    std::uint64_t nextTree = 0;
    for (const CacheCascade& c : cascades) {
        if (c.firstTree != nextTree || c.trees > n.trees - nextTree || c.firstFeature > n.features ||
            c.features > n.features - c.firstFeature)
            return bad("a cascade's trees or feature pixels lie outside the arrays");
        Model::Cascade cascade;
        cascade.firstTree = static_cast<std::size_t>(c.firstTree);
        cascade.trees = static_cast<std::size_t>(c.trees);
        for (std::uint64_t f = c.firstFeature; f < c.firstFeature + c.features; ++f) {
            if (anchors[f] >= n.dims / 2) return bad("a feature pixel hangs from a shape point that does not exist");
            cascade.anchorIdx.push_back(anchors[f]);
            cascade.deltas.emplace_back(deltas[2 * f], deltas[2 * f + 1]);
        }
        for (std::uint64_t t = c.firstTree; t < c.firstTree + c.trees; ++t) {
            const Model::Tree& tree = trees[t];
            const std::uint64_t leafCount = std::uint64_t{tree.splits} + 1;
            if ((leafCount & (leafCount - 1)) != 0 || tree.firstSplit + std::uint64_t{tree.splits} > n.splits ||
                tree.firstLeaf + leafCount > n.leaves)
                return bad("a tree's splits or leaves lie outside the arrays");
            for (std::uint32_t s = 0; s < tree.splits; ++s) {
                const QuantizedSplit& split = splits[tree.firstSplit + s];
                if (split.idx1 >= c.features || split.idx2 >= c.features)
                    return bad("a split uses a feature pixel its cascade lacks");
            }
        }
        nextTree += c.trees;
        m->cascades.push_back(std::move(cascade));
    }
    if (nextTree != n.trees) return bad("trees that belong to no cascade");
    m->trees = trees;
    m->splits = splits;
    m->scales = scales;
    m->leaves = leaves;
    m->mapped = std::move(cache);
    return m;
}

}  // namespace

std::unique_ptr<const QuantizedShapePredictor> QuantizedShapePredictor::load(const std::filesystem::path& model,
                                                                             const std::filesystem::path& cacheDir) {
    const std::optional<std::string> stamp = cacheDir.empty() ? std::nullopt : sourceFileStamp(model);
    if (!stamp) return std::make_unique<const QuantizedShapePredictor>(model);
    const std::filesystem::path file = cacheDir / (model.filename().string() + ".quantized");
    std::string why;
    if (auto cache = CacheFile::open(file, kCacheKind, *stamp, why)) {
        if (auto m = modelFromCache(std::move(cache), why))
            return std::unique_ptr<const QuantizedShapePredictor>(new QuantizedShapePredictor(std::move(m), file));
    }
    if (!why.empty()) spdlog::info("{}: {}: converting {} again", file.string(), why, model.string());
    auto converted = std::make_unique<const QuantizedShapePredictor>(model);
    // A model file replaced while it was read: its cache would carry the wrong stamp.
    if (sourceFileStamp(model) != stamp) return converted;
    try {
        writeCache(*converted->model_, file, *stamp);
        spdlog::info("landmark model {} converted and cached in {}", model.string(), file.string());
    } catch (const BoothError& e) {
        spdlog::warn("landmark model cache not written, so the model is converted at every start: {}", e.what());
    }
    return converted;
}

int QuantizedShapePredictor::parts() const { return static_cast<int>(model_->dims / 2); }

std::size_t QuantizedShapePredictor::modelBytes() const {
    return model_->trees.size() * sizeof(Model::Tree) + model_->splits.size() * sizeof(QuantizedSplit) +
           model_->scales.size() * sizeof(float) + model_->leaves.size() * sizeof(std::int16_t);
}

std::vector<cv::Point2d> QuantizedShapePredictor::predictSubpixel(const cv::Mat& grey, const cv::Rect& face) const {
    if (grey.type() != CV_8UC1) throw BoothError(ErrorKind::Internal, "", "shape predictor: an 8-bit grey image is expected");
    const Model& m = *model_;
    const dlib::cv_image<unsigned char> image(grey);
    const dlib::rectangle box(face.x, face.y, face.x + face.width - 1, face.y + face.height - 1);
    // As dlib's shape_predictor::operator(): start from the mean shape; each cascade samples its pixels relative
    // to the current shape, and every tree of it adds the leaf its splits lead to.
    dlib::matrix<float, 0, 1> shape = m.initialShape;
    std::vector<float> features;
    for (const auto& cascade : m.cascades) {
        dlib::impl::extract_feature_pixel_values(image, box, shape, m.initialShape, cascade.anchorIdx, cascade.deltas,
                                                 features);
        float* out = &shape(0);
        for (std::size_t t = cascade.firstTree; t < cascade.firstTree + cascade.trees; ++t) {
            const Model::Tree& tree = m.trees[t];
            const QuantizedSplit* splits = &m.splits[tree.firstSplit];
            std::uint32_t i = 0;
            while (i < tree.splits)
                i = features[splits[i].idx1] - features[splits[i].idx2] > splits[i].thresh ? 2 * i + 1 : 2 * i + 2;
            const std::size_t leaf = tree.firstLeaf + (i - tree.splits);
            const float scale = m.scales[leaf];
            const std::int16_t* q = &m.leaves[leaf * m.dims];
            for (std::size_t k = 0; k < m.dims; ++k) out[k] += scale * static_cast<float>(q[k]);
        }
    }
    const dlib::point_transform_affine toImage = dlib::impl::unnormalizing_tform(box);
    std::vector<cv::Point2d> points(m.dims / 2);
    for (std::size_t p = 0; p < points.size(); ++p) {
        const dlib::dpoint at = toImage(dlib::dpoint(dlib::impl::location(shape, p)));
        points[p] = cv::Point2d(at.x(), at.y());
    }
    return points;
}

std::vector<cv::Point> QuantizedShapePredictor::predict(const cv::Mat& grey, const cv::Rect& face) const {
    const std::vector<cv::Point2d> exact = predictSubpixel(grey, face);
    std::vector<cv::Point> points(exact.size());
    for (std::size_t p = 0; p < points.size(); ++p) {
        const dlib::point rounded(dlib::dpoint(exact[p].x, exact[p].y));  // dlib's rounding to whole pixels
        points[p] = cv::Point(static_cast<int>(rounded.x()), static_cast<int>(rounded.y()));
    }
    return points;
}

}  // namespace avatarbooth
