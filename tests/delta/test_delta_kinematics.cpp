// Delta kinematics (parts/DeltaKinematics) against seed 004's numbers
// (../shared/seeds/digests/seed_004_delta.md §2 and §8): f = 233.2 mm,
// e = 80 mm, r_f = 60 mm, r_e = 350 mm; theta > 0 below the base plane.
#include <gtest/gtest.h>

#include "parts/DeltaKinematics.hpp"

namespace avrbench {
namespace {

const DeltaGeometry kSeed004{};

TEST(DeltaKinematics, ForwardMatchesTheThesisFirmwaresFigures) {
    // Digest §2: FK(0,0,0) = (0, 0, -33.412 cm); FK(90,90,90) = (0, 0, -40.719 cm).
    const auto home = delta_forward(kSeed004, {0, 0, 0});
    ASSERT_TRUE(home.has_value());
    EXPECT_NEAR(home->x(), 0.0, 1e-9);
    EXPECT_NEAR(home->y(), 0.0, 1e-9);
    EXPECT_NEAR(home->z(), -334.12, 0.01);
    const auto down = delta_forward(kSeed004, {90, 90, 90});
    ASSERT_TRUE(down.has_value());
    EXPECT_NEAR(down->z(), -407.19, 0.01);
}

TEST(DeltaKinematics, InverseMatchesTheDigestsWorkPoints) {
    struct Row {
        Eigen::Vector3d p_mm;
        std::array<double, 3> theta_deg;  // digest §8.4, to 0.01 deg
    };
    const Row rows[] = {
        {{0, 0, -310}, {-25.57, -25.57, -25.57}},
        {{-100, 0, -310}, {-8.65, 18.36, -37.31}},
        {{-100, 0, -320}, {1.14, 26.54, -25.91}},
        {{-33, -67, -310}, {-38.82, 4.53, -14.18}},
        {{-33, 67, -340}, {31.81, 11.90, -4.77}},
        {{100, -67, -340}, {6.34, 10.45, 57.43}},
        {{100, 67, -340}, {44.49, -9.12, 40.83}},
    };
    for (const auto& r : rows) {
        const auto theta = delta_inverse(kSeed004, r.p_mm);
        ASSERT_TRUE(theta.has_value()) << r.p_mm.transpose();
        for (int k = 0; k < 3; ++k) EXPECT_NEAR((*theta)[k], r.theta_deg[k], 0.006) << r.p_mm.transpose() << " arm " << k + 1;
    }
}

TEST(DeltaKinematics, ForwardOfInverseIsThePointAcrossTheWorkArea) {
    // Digest §8.7: FK(IK(p)) = p within 1e-3 cm for the work points; here over
    // the whole 200 x 200 mm square at z = -300 mm and the program's heights.
    for (double z : {-300.0, -310.0, -320.0, -340.0}) {
        for (double x = -100; x <= 100; x += 25) {
            for (double y = -100; y <= 100; y += 25) {
                const Eigen::Vector3d p(x, y, z);
                const auto theta = delta_inverse(kSeed004, p);
                ASSERT_TRUE(theta.has_value()) << p.transpose();
                const auto back = delta_forward(kSeed004, *theta);
                ASSERT_TRUE(back.has_value()) << p.transpose();
                EXPECT_LT((*back - p).norm(), 0.01) << p.transpose();
            }
        }
    }
}

TEST(DeltaKinematics, OutOfReachIsNoSolution) {
    EXPECT_FALSE(delta_inverse(kSeed004, Eigen::Vector3d(0, 0, -500)).has_value());  // below r_f + r_e
    EXPECT_FALSE(delta_inverse(kSeed004, Eigen::Vector3d(400, 0, -300)).has_value());
}

}  // namespace
}  // namespace avrbench
