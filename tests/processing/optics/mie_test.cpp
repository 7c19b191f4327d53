// The Mie series against published values:
//  - W. J. Wiscombe, "Mie scattering calculations: advances in technique and fast,
//    vector-speed computer codes", NCAR/TN-140+STR (1979, revised 1996), the MIEV0 test
//    cases 5-19 (Q_ext, Q_sca, g Q_sca; Wiscombe writes m = n - i k, we write n + i k);
//  - the same report's appendix, m = 1.5 and 1.5 + 0.1i at x = 10 ... 5000 (Q_ext, Q_sca, g);
//  - C. F. Bohren, D. R. Huffman, "Absorption and scattering of light by small particles"
//    (1983), Appendix A, p. 482: the BHMIE example (sphere of radius 0.525 um, m = 1.55, in
//    light of 0.6328 um): Q_sca, Q_back and the normalised S11, POL, S33, S34 at 0..180 deg.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>

#include "tomorig/core/error.h"
#include "tomorig/processing/optics/mie.h"

namespace tomorig::optics {
namespace {

struct WiscombeCase {
  double x;
  std::complex<double> m;
  double q_ext, q_sca, g_q_sca;
};

// MIEV0 test cases 5-19 (cases 1-4 are perfect conductors, which this code does not model).
const WiscombeCase kWiscombe[] = {
    {0.099, {0.75, 0}, 7.417859e-06, 7.417859e-06, 1.074279e-08},
    {0.101, {0.75, 0}, 8.033542e-06, 8.033542e-06, 1.211000e-08},
    {10, {0.75, 0}, 2.232265, 2.232265, 2.001164},
    {1000, {0.75, 0}, 1.997908, 1.997908, 1.688121},
    {1, {1.33, 1e-5}, 9.395198e-02, 9.392330e-02, 1.733048e-02},
    {100, {1.33, 1e-5}, 2.101321, 2.096594, 1.821854},
    {10000, {1.33, 1e-5}, 2.004089, 1.723857, 1.564987},
    {0.055, {1.5, 1}, 1.014910e-01, 1.131687e-05, 5.558541e-09},
    {0.056, {1.5, 1}, 1.033467e-01, 1.216311e-05, 6.193255e-09},
    {1, {1.5, 1}, 2.336321, 6.634538e-01, 1.274736e-01},
    {100, {1.5, 1}, 2.097502, 1.283697, 1.091466},
    {10000, {1.5, 1}, 2.004368, 1.236574, 1.046525},
    {1, {10, 10}, 2.532993, 2.049405, -2.267961e-01},
    {100, {10, 10}, 2.071124, 1.836785, 1.021648},
    {10000, {10, 10}, 2.005914, 1.795393, 9.842238e-01},
};

// Relative agreement to the 7 digits the tables give (plus rounding of the last one).
void expect_close(double got, double want, const char* what, double x) {
  EXPECT_NEAR(got, want, 2e-6 * std::abs(want) + 1e-12) << what << " at x = " << x;
}

TEST(Mie, MatchesWiscombeTestCases) {
  for (const WiscombeCase& c : kWiscombe) {
    const MieSeries mie(c.x, c.m);
    const MieEfficiencies& q = mie.efficiencies();
    expect_close(q.q_ext, c.q_ext, "Q_ext", c.x);
    expect_close(q.q_sca, c.q_sca, "Q_sca", c.x);
    expect_close(q.g * q.q_sca, c.g_q_sca, "g Q_sca", c.x);
  }
}

TEST(Mie, MatchesWiscombeDielectricSpheres) {
  struct Case {
    double x;
    std::complex<double> m;
    double q_ext, q_sca, g;
  };
  const Case cases[] = {
      {10, {1.5, 0}, 2.881999, 2.881999, 0.742913},     {100, {1.5, 0}, 2.094388, 2.094388, 0.818246},
      {1000, {1.5, 0}, 2.013945, 2.013945, 0.827882},   {5000, {1.5, 0}, 2.008650, 2.008650, 0.829592},
      {10, {1.5, 0.1}, 2.459791, 1.235144, 0.922350},   {100, {1.5, 0.1}, 2.089822, 1.132134, 0.950392},
      {1000, {1.5, 0.1}, 2.019703, 1.106932, 0.950880}, {5000, {1.5, 0.1}, 2.006775, 1.099193, 0.950650},
  };
  for (const Case& c : cases) {
    const MieSeries mie(c.x, c.m);
    expect_close(mie.efficiencies().q_ext, c.q_ext, "Q_ext", c.x);
    expect_close(mie.efficiencies().q_sca, c.q_sca, "Q_sca", c.x);
    expect_close(mie.efficiencies().g, c.g, "g", c.x);
  }
}

TEST(Mie, MatchesBohrenHuffmanExampleWithAngularAmplitudes) {
  const double x = 2.0 * M_PI * 0.525 / 0.6328;
  const MieSeries mie(x, {1.55, 0.0});
  EXPECT_NEAR(mie.efficiencies().q_sca, 3.10543, 1e-5);
  EXPECT_NEAR(mie.efficiencies().q_ext, 3.10543, 1e-5);
  EXPECT_NEAR(mie.efficiencies().q_back, 2.92534, 1e-5);
  // B&H's table, every 9 degrees: S11 / S11(0), POL = -S12 / S11, S33 / S11, S34 / S11.
  const double s11[] = {0.100000e+01, 0.785390e+00, 0.356897e+00, 0.766119e-01, 0.355355e-01, 0.701845e-01,
                        0.574313e-01, 0.219660e-01, 0.125959e-01, 0.173750e-01, 0.124601e-01, 0.679093e-02,
                        0.954239e-02, 0.863419e-02, 0.227421e-02, 0.543998e-02, 0.160243e-01, 0.188852e-01,
                        0.195254e-01, 0.301676e-01, 0.383189e-01};
  const double pol[] = {0.000000e+00,  -0.459811e-02, -0.458541e-01, -0.364744e+00, -0.534997e+00, 0.959953e-02,
                        0.477927e-01,  -0.440604e+00, -0.831996e+00, 0.341670e-01,  0.230462e+00,  -0.713472e+00,
                        -0.756255e+00, -0.281215e+00, -0.239612e+00, -0.850804e+00, -0.706334e+00, -0.891081e+00,
                        -0.783319e+00, -0.196194e+00, 0.000000e+00};
  const double s33[] = {0.100000e+01,  0.999400e+00, 0.986022e+00, 0.843603e+00,  0.686967e+00,  0.959825e+00,
                        0.985371e+00,  0.648043e+00, 0.203255e+00, 0.795354e+00,  0.937497e+00,  -0.717397e-02,
                        -0.394748e-01, 0.536251e+00, 0.967602e+00, 0.187531e+00,  0.495254e+00,  0.453277e+00,
                        -0.391613e+00, -0.962069e+00, -0.100000e+01};
  const double s34[] = {0.000000e+00,  0.343261e-01,  0.160184e+00,  0.394076e+00, -0.491787e+00, -0.280434e+00,
                        0.163584e+00,  0.621216e+00,  -0.516208e+00, -0.605182e+00, 0.260742e+00, 0.700647e+00,
                        -0.653085e+00, -0.795835e+00, 0.795798e-01,  -0.490882e+00, -0.505781e+00, -0.226817e-01,
                        0.482752e+00,  0.189556e+00,  0.000000e+00};
  const double forward = mie.amplitudes(0.0).s11();
  for (int i = 0; i < 21; ++i) {
    const MieAmplitudes s = mie.amplitudes(i * 9.0 * M_PI / 180.0);
    const double n1 = std::norm(s.s1), n2 = std::norm(s.s2);
    const double m11 = 0.5 * (n1 + n2);
    const std::complex<double> s2s1 = s.s2 * std::conj(s.s1);
    EXPECT_NEAR(m11 / forward, s11[i], 2e-6 + 2e-6 * s11[i]) << "S11 at " << 9 * i << " deg";
    EXPECT_NEAR((n1 - n2) / (n1 + n2), pol[i], 5e-6) << "POL at " << 9 * i << " deg";
    EXPECT_NEAR(s2s1.real() / m11, s33[i], 5e-6) << "S33 at " << 9 * i << " deg";
    EXPECT_NEAR(s2s1.imag() / m11, s34[i], 5e-6) << "S34 at " << 9 * i << " deg";
  }
}

TEST(Mie, ForwardAmplitudeGivesExtinctionAndConeIntegralGivesScattering) {
  // Optical theorem (B&H 4.76): Q_ext = 4 / x^2 Re S(0); and the full-sphere integral of the
  // unpolarised intensity is x^2 Q_sca. A water droplet of 10 um in green light.
  const double x = M_PI * 10.0 / 0.525;
  const MieSeries mie(x, {1.334, 1e-9});
  EXPECT_NEAR(4.0 / (x * x) * mie.amplitudes(0.0).s1.real(), mie.efficiencies().q_ext, 1e-9);
  EXPECT_NEAR(mie.forward_cone_integral(M_PI) / (x * x * mie.efficiencies().q_sca), 1.0, 1e-4);
}

TEST(Mie, RefusesBadInput) {
  EXPECT_THROW(MieSeries(0.0, {1.33, 0}), Error);
  EXPECT_THROW(MieSeries(-1.0, {1.33, 0}), Error);
  EXPECT_THROW(MieSeries(NAN, {1.33, 0}), Error);
  EXPECT_THROW(MieSeries(10.0, {1.33, -0.1}), Error);
  EXPECT_THROW(MieSeries(10.0, {0.0, 0}), Error);
  try {
    MieSeries(10.0, {1.33, -0.1});
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::bad_input);
    EXPECT_NE(std::string(e.what()).find("imaginary"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace tomorig::optics
