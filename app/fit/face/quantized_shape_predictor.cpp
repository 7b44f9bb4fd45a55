// dlib's shape predictor with 16-bit leaves: read tree by tree from dlib's file, walked as dlib walks it.
#include "fit/face/quantized_shape_predictor.h"

#include "common/error.h"

#include <dlib/image_processing/shape_predictor.h>
#include <dlib/opencv/cv_image.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <string>

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
    std::vector<Tree> trees;
    std::vector<QuantizedSplit> splits;
    // Leaf l's vector is scales[l] * leaves[l * dims .. (l + 1) * dims): each leaf scaled to its own largest
    // value, so its rounding error is at most 1/65534 of that. Summed over the trees that moves the shape by about
    // 1e-5 of the face box, which now and then rounds a point to the next pixel or sends a later tree down the
    // other branch (tests/data: mean 0.09 px from dlib's, at most 2 px).
    std::vector<float> scales;
    std::vector<std::int16_t> leaves;
    std::size_t dims = 0;  // 2 x parts
};

namespace {

[[noreturn]] void notAModel(const std::filesystem::path& file, const std::string& why) {
    throw BoothError(ErrorKind::BadConfig, file.string(), "is not a dlib shape predictor: " + why);
}

// Appends one of dlib's trees to the model, its leaves rounded to 16 bits.
void addTree(QuantizedShapePredictor::Model& m, const dlib::impl::regression_tree& tree,
             const std::filesystem::path& file) {
    const std::size_t leafCount = tree.leaf_values.size();
    if (leafCount == 0 || (leafCount & (leafCount - 1)) != 0 || tree.splits.size() + 1 != leafCount)
        notAModel(file, "a tree has " + std::to_string(tree.splits.size()) + " splits and " +
                            std::to_string(leafCount) + " leaves (a full binary tree is expected)");
    if (m.splits.size() + tree.splits.size() > std::numeric_limits<std::uint32_t>::max() ||
        m.scales.size() + leafCount > std::numeric_limits<std::uint32_t>::max())
        notAModel(file, "too many trees");
    QuantizedShapePredictor::Model::Tree t;
    t.firstSplit = static_cast<std::uint32_t>(m.splits.size());
    t.splits = static_cast<std::uint32_t>(tree.splits.size());
    t.firstLeaf = static_cast<std::uint32_t>(m.scales.size());
    for (const auto& s : tree.splits) {
        if (s.idx1 > std::numeric_limits<std::uint16_t>::max() || s.idx2 > std::numeric_limits<std::uint16_t>::max())
            notAModel(file, "a split uses feature " + std::to_string(std::max(s.idx1, s.idx2)) +
                                " (at most 65535 features per cascade are supported)");
        m.splits.push_back({static_cast<std::uint16_t>(s.idx1), static_cast<std::uint16_t>(s.idx2), s.thresh});
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
        m.scales.push_back(scale);
        for (long k = 0; k < leaf.size(); ++k)
            m.leaves.push_back(scale > 0.0f ? static_cast<std::int16_t>(std::lround(leaf(k) / scale)) : 0);
    }
    m.trees.push_back(t);
}

}  // namespace

QuantizedShapePredictor::QuantizedShapePredictor(const std::filesystem::path& file) {
    // A plain stream, read front to back: the file may be a pipe (dlib's own proxy_deserialize seeks).
    std::ifstream in(file, std::ios::binary);
    if (!in) throw BoothError(ErrorKind::BadConfig, file.string(), std::string("cannot be read: ") + std::strerror(errno));
    auto m = std::make_unique<Model>();
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
            cascade.firstTree = m->trees.size();
            cascade.trees = trees;
            for (unsigned long t = 0; t < trees; ++t) {
                using dlib::deserialize;  // the tree's own (a friend, found by argument-dependent lookup)
                deserialize(tree, in);
                if (m->trees.empty()) {  // the first tree tells the model's size: one block for all the leaves
                    const std::size_t expected = cascades * trees * tree.leaf_values.size();
                    m->trees.reserve(cascades * trees);
                    m->splits.reserve(expected);
                    m->scales.reserve(expected);
                    m->leaves.reserve(expected * m->dims);
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
            for (const unsigned long a : anchors[c])
                if (a >= m->dims / 2) notAModel(file, "a feature pixel hangs from a shape point that does not exist");
            for (std::size_t t = cascade.firstTree; t < cascade.firstTree + cascade.trees; ++t)
                for (std::uint32_t s = 0; s < m->trees[t].splits; ++s) {
                    const QuantizedSplit& split = m->splits[m->trees[t].firstSplit + s];
                    if (split.idx1 >= anchors[c].size() || split.idx2 >= anchors[c].size())
                        notAModel(file, "a split in cascade " + std::to_string(c) + " uses a feature pixel it lacks");
                }
            cascade.anchorIdx = std::move(anchors[c]);
            cascade.deltas = std::move(deltas[c]);
        }
    } catch (const dlib::serialization_error& e) {
        notAModel(file, e.what());
    }
    m->trees.shrink_to_fit();
    model_ = std::move(m);
}

QuantizedShapePredictor::~QuantizedShapePredictor() = default;

int QuantizedShapePredictor::parts() const { return static_cast<int>(model_->dims / 2); }

std::size_t QuantizedShapePredictor::modelBytes() const {
    return model_->trees.size() * sizeof(Model::Tree) + model_->splits.size() * sizeof(QuantizedSplit) +
           model_->scales.size() * sizeof(float) + model_->leaves.size() * sizeof(std::int16_t);
}

std::vector<cv::Point> QuantizedShapePredictor::predict(const cv::Mat& grey, const cv::Rect& face) const {
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
    std::vector<cv::Point> points(m.dims / 2);
    for (std::size_t p = 0; p < points.size(); ++p) {
        const dlib::point rounded = toImage(dlib::impl::location(shape, p));  // dlib's rounding to whole pixels
        points[p] = cv::Point(static_cast<int>(rounded.x()), static_cast<int>(rounded.y()));
    }
    return points;
}

}  // namespace avatarbooth
