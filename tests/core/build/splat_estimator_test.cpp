// Splat attributes: encodings, and the per-node estimates on surfaces with known normal and
// spacing, for leaves and for parents (which hold a sample of their children's points).
#include "build/splat_encoding.hpp"
#include "build/splat_estimator.hpp"
#include "hierarchy_test_support.hpp"
#include "test_files.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <glm/geometric.hpp>
#include <gtest/gtest.h>
#include <random>
#include <vector>

namespace omicron {
namespace {

// Calls visit(node, radii, normals) with the decoded attributes of every node of `level`
// (every level when level < 0).
void forEachNodeSplats(const Hierarchy& hierarchy, int level,
                       const std::function<void(const OctreeNode&, const std::vector<float>&,
                                                const std::vector<glm::vec3>&)>& visit) {
    NodeSplats splats;
    SplatScratch scratch;
    std::vector<float> radii;
    std::vector<glm::vec3> normals;
    for (int l = 0; l <= hierarchy.maxLevel(); ++l) {
        if (level >= 0 && l != level) {
            continue;
        }
        for (std::size_t i = 0; i < hierarchy.nodeCount(l); ++i) {
            const OctreeNode& node = hierarchy.node(l, i);
            hierarchy.nodeSplats(node, splats, scratch);
            EXPECT_EQ(splats.radii.size(), node.pointCount);
            radii.clear();
            normals.clear();
            for (std::uint32_t p = 0; p < node.pointCount; ++p) {
                radii.push_back(decodeRadius(splats.radii[p]) * node.splatScale);
                normals.push_back(splats.normals.empty()
                                      ? hierarchy.cloud().normals()[node.heldPoint(p)]
                                      : decodeOctahedral(splats.normals[p]));
            }
            visit(node, radii, normals);
        }
    }
}

TEST(SplatEncoding, OctahedralNormalsRoundTrip) {
    std::mt19937_64 random(4);
    std::normal_distribution<float> gauss;
    for (int i = 0; i < 10000; ++i) {
        const glm::vec3 n = glm::normalize(glm::vec3(gauss(random), gauss(random), gauss(random)));
        const glm::vec3 back = decodeOctahedral(encodeOctahedral(n));
        EXPECT_GT(glm::dot(n, back), 0.99999f) << n.x << " " << n.y << " " << n.z;
    }
    for (const glm::vec3 axis :
         {glm::vec3(0, 0, 1), glm::vec3(0, 0, -1), glm::vec3(1, 0, 0), glm::vec3(0, -1, 0)}) {
        EXPECT_GT(glm::dot(axis, decodeOctahedral(encodeOctahedral(axis))), 0.99999f);
    }
    EXPECT_EQ(encodeOctahedral(glm::vec3(0.0f)), kUnknownNormal);
    EXPECT_EQ(decodeOctahedral(kUnknownNormal), glm::vec3(0.0f));
}

TEST(SplatEncoding, RadiusEncodingIsWithinAQuarterPercent) {
    for (float r = 1e-9f; r < 1.0f; r *= 1.37f) {
        const float back = decodeRadius(encodeRadius(r));
        if (r < std::ldexp(1.0f, -32)) {
            EXPECT_FLOAT_EQ(back, std::ldexp(1.0f, -32)) << "clamped to the smallest code";
        } else {
            EXPECT_NEAR(back / r, 1.0f, 0.0025f) << r;
        }
    }
    EXPECT_EQ(encodeRadius(0.0f), 0u);
}

// A square grid of n x n points on the plane z = 0.5, spacing 1/n, plus a tiny jitter.
test::SyntheticCloud gridPlane(int n) {
    test::SyntheticCloud cloud;
    cloud.info.path = "grid plane";
    std::mt19937_64 random(9);
    std::uniform_real_distribution<float> jitter(-0.05f, 0.05f);
    for (int y = 0; y < n; ++y) {
        for (int x = 0; x < n; ++x) {
            cloud.points.positions.push_back(
                glm::vec3((x + 0.5f + jitter(random)) / n, (y + 0.5f + jitter(random)) / n, 0.5f));
        }
    }
    cloud.info.pointCount = cloud.points.size();
    return cloud;
}

TEST(SplatEstimator, PlaneLeavesGetItsNormalAndItsSpacing) {
    const int n = 512;
    const auto result = test::buildSynthetic(gridPlane(n), BuildOptions{}, 65536);
    const Hierarchy& hierarchy = result.builder->hierarchy();
    ASSERT_TRUE(hierarchy.estimatesNormals());
    std::vector<float> allRadii;
    std::size_t upright = 0;
    forEachNodeSplats(hierarchy, hierarchy.maxLevel(),
                      [&](const OctreeNode&, const std::vector<float>& radii,
                          const std::vector<glm::vec3>& normals) {
                          for (std::size_t p = 0; p < radii.size(); ++p) {
                              upright += normals[p].z > 0.999f ? 1 : 0;
                              allRadii.push_back(radii[p]);
                          }
                      });
    ASSERT_EQ(allRadii.size(), result.cloud->sortedEnd()) << "the leaves hold every point";
    EXPECT_EQ(upright, allRadii.size()) << "every normal of a plane is its normal, facing +z";
    std::sort(allRadii.begin(), allRadii.end());
    const float spacing = 1.0f / n;
    EXPECT_NEAR(allRadii[allRadii.size() / 2] / spacing, 1.0f, 0.25f) << "median radius ~ spacing";
    EXPECT_GT(allRadii.front(), 0.5f * spacing);
    EXPECT_LT(allRadii.back(), 2.0f * spacing);
}

TEST(SplatEstimator, ParentSplatsCoverTheAreaOfTheirChildren) {
    // A parent keeps `ratio` of its children's points: its spacing, hence its radius, grows by
    // sqrt(1 / ratio) per level up, so its fewer splats still cover the plane.
    const int n = 512;
    for (const double ratio : {0.2, 0.25}) {
        BuildOptions options;
        options.ratio = ratio;
        const auto result = test::buildSynthetic(gridPlane(n), options, 65536);
        const Hierarchy& hierarchy = result.builder->hierarchy();
        for (int level = hierarchy.maxLevel(); level >= hierarchy.maxLevel() - 3; --level) {
            std::vector<float> radii;
            std::size_t upright = 0;
            forEachNodeSplats(hierarchy, level,
                              [&](const OctreeNode&, const std::vector<float>& r,
                                  const std::vector<glm::vec3>& normals) {
                                  radii.insert(radii.end(), r.begin(), r.end());
                                  for (const glm::vec3& normal : normals) {
                                      upright += normal.z > 0.999f ? 1 : 0;
                                  }
                              });
            ASSERT_FALSE(radii.empty());
            EXPECT_EQ(upright, radii.size()) << "level " << level;
            std::sort(radii.begin(), radii.end());
            const double expected = std::pow(1.0 / ratio, 0.5 * (hierarchy.maxLevel() - level)) / n;
            EXPECT_NEAR(radii[radii.size() / 2] / expected, 1.0, 0.25)
                << "ratio " << ratio << ", level " << level;
        }
    }
}

TEST(SplatEstimator, TiltedPlaneNormal) {
    // The plane x + y + z = 1.5 through the cube: normal (1, 1, 1) / sqrt(3).
    test::SyntheticCloud cloud = test::makeCloud(test::Shape::Random, 60000, 3);
    for (glm::vec3& p : cloud.points.positions) {
        p.z = std::clamp(1.5f - p.x - p.y, 0.0f, 1.0f);
    }
    cloud.info.attributes = {};
    cloud.points.attributes = {};
    cloud.points.colors.clear();
    const auto result = test::buildSynthetic(cloud, BuildOptions{}, 65536);
    const Hierarchy& hierarchy = result.builder->hierarchy();
    const glm::vec3 expected = glm::normalize(glm::vec3(1.0f));
    std::size_t good = 0, onPlane = 0;
    forEachNodeSplats(hierarchy, hierarchy.maxLevel(),
                      [&](const OctreeNode& node, const std::vector<float>&,
                          const std::vector<glm::vec3>& normals) {
                          for (std::uint32_t p = 0; p < node.pointCount; ++p) {
                              const glm::vec3 q = result.cloud->positions()[node.heldPoint(p)];
                              if (q.z <= 0.0f || q.z >= 1.0f) {
                                  continue; // clamped onto a cube face: another plane
                              }
                              ++onPlane;
                              good += glm::dot(normals[p], expected) > 0.99f ? 1 : 0;
                          }
                      });
    EXPECT_GT(double(good), 0.95 * double(onPlane));
}

TEST(SplatEstimator, LineHasNoNormalButASpacing) {
    const auto result =
        test::buildSynthetic(test::makeCloud(test::Shape::Line, 20000, 5), BuildOptions{});
    std::size_t points = 0;
    forEachNodeSplats(result.builder->hierarchy(), -1,
                      [&](const OctreeNode& node, const std::vector<float>& radii,
                          const std::vector<glm::vec3>& normals) {
                          for (std::size_t p = 0; p < radii.size(); ++p, ++points) {
                              ASSERT_EQ(normals[p], glm::vec3(0.0f)) << "a line has no normal";
                              ASSERT_GT(radii[p], 0.0f);
                              ASSERT_LE(radii[p], std::ldexp(1.0f, -node.level()));
                          }
                      });
    EXPECT_GT(points, 20000u);
}

TEST(SplatEstimator, CoincidentPointsGetHalfTheirCellAsRadius) {
    // Nothing to measure: the fallback is half the edge of the fine cell they fall in.
    const auto result =
        test::buildSynthetic(test::makeCloud(test::Shape::AllIdentical, 500, 5), BuildOptions{});
    forEachNodeSplats(result.builder->hierarchy(), -1,
                      [&](const OctreeNode& node, const std::vector<float>& radii,
                          const std::vector<glm::vec3>& normals) {
                          const float halfNodeEdge = std::ldexp(1.0f, -(node.level() + 1));
                          for (std::size_t p = 0; p < radii.size(); ++p) {
                              ASSERT_GT(radii[p], 0.0f);
                              ASSERT_LE(radii[p], halfNodeEdge * 1.001f);
                              ASSERT_EQ(normals[p], glm::vec3(0.0f));
                          }
                      });
}

TEST(SplatEstimator, SparseLeafBorrowsItsSiblingsShape) {
    // At depth 7 a 256 x 256 grid puts about 4 points in each leaf: too few for an estimate of
    // their own, so every leaf borrows its sibling group on the same plane.
    const int n = 256;
    test::SyntheticCloud cloud = gridPlane(n);
    const auto result = test::buildSynthetic(cloud, BuildOptions{}, 65536);
    const Hierarchy& hierarchy = result.builder->hierarchy();
    std::size_t sparseLeaves = 0;
    forEachNodeSplats(hierarchy, hierarchy.maxLevel(),
                      [&](const OctreeNode& node, const std::vector<float>& radii,
                          const std::vector<glm::vec3>& normals) {
                          if (node.pointCount >= 8) {
                              return;
                          }
                          ++sparseLeaves;
                          const SparseSplatRegion region = hierarchy.sparseSplatRegion(node);
                          EXPECT_LE(region.begin, node.coveredBegin);
                          EXPECT_GE(region.begin + region.count,
                                    node.coveredBegin + node.coveredCount);
                          for (std::size_t p = 0; p < radii.size(); ++p) {
                              EXPECT_GT(normals[p].z, 0.999f);
                              EXPECT_NEAR(radii[p] * n, 1.0f, 0.5f);
                          }
                      });
    EXPECT_GT(sparseLeaves, 1000u);
}

TEST(SplatEstimator, EstimatesAreDeterministicAcrossThreadsAndCalls) {
    const auto cloud = test::makeCloud(test::Shape::Random, 30000, 21);
    BuildOptions options;
    options.threads = 1;
    const auto one = test::buildSynthetic(cloud, options);
    options.threads = 2;
    options.worklistSize = 8;
    const auto two = test::buildSynthetic(cloud, options, 777);
    EXPECT_EQ(test::fingerprint(one.builder->hierarchy()),
              test::fingerprint(two.builder->hierarchy()));
    EXPECT_EQ(test::fingerprint(one.builder->hierarchy()),
              test::fingerprint(one.builder->hierarchy()));
}

TEST(SplatEstimator, InputNormalsAreKept) {
    OMICRON_REQUIRE_SHARED_FILE(path, "bunny.ply");
    const auto result = test::buildFile(path, BuildOptions{});
    const Hierarchy& hierarchy = result.builder->hierarchy();
    EXPECT_FALSE(hierarchy.estimatesNormals());
    NodeSplats splats;
    SplatScratch scratch;
    hierarchy.nodeSplats(hierarchy.node(0, 0), splats, scratch);
    EXPECT_TRUE(splats.normals.empty()) << "nothing estimated where the input has normals";
    forEachNodeSplats(hierarchy, -1,
                      [&](const OctreeNode& node, const std::vector<float>& radii,
                          const std::vector<glm::vec3>& normals) {
                          for (std::uint32_t p = 0; p < node.pointCount; ++p) {
                              ASSERT_EQ(normals[p], result.cloud->normals()[node.heldPoint(p)]);
                              ASSERT_GT(radii[p], 0.0f);
                              ASSERT_TRUE(std::isfinite(radii[p]));
                          }
                      });
}

TEST(SplatEstimator, RealScanWithoutNormalsGetsUnitNormalsAlmostEverywhere) {
    OMICRON_REQUIRE_SHARED_FILE(path, "autzen_trim.ply");
    const auto result = test::buildFile(path, BuildOptions{});
    const Hierarchy& hierarchy = result.builder->hierarchy();
    EXPECT_TRUE(hierarchy.estimatesNormals());
    EXPECT_EQ(result.builder->statistics().splatBytes, 0u) << "a build holds no attributes";
    std::size_t known = 0, points = 0;
    forEachNodeSplats(hierarchy, -1,
                      [&](const OctreeNode&, const std::vector<float>& radii,
                          const std::vector<glm::vec3>& normals) {
                          for (std::size_t p = 0; p < radii.size(); ++p, ++points) {
                              if (normals[p] != glm::vec3(0.0f)) {
                                  ++known;
                                  ASSERT_NEAR(glm::length(normals[p]), 1.0f, 1e-4f);
                              }
                              ASSERT_GT(radii[p], 0.0f);
                          }
                      });
    EXPECT_GT(double(known), 0.95 * double(points));
}

} // namespace
} // namespace omicron
