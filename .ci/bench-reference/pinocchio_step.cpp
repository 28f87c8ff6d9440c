// Per-call times of Pinocchio's ABA, RNEA, CRBA and of one discrete step as the reference README
// writes it ((M + h·D)·v₁ = M·v₀ + h·(u − nle), q₁ = q₀ + h·v₁: CRBA, nonLinearEffects, LLT), in C++
// with no Python in the loop, on the URDFs given (fixed base; mimic joints coupled).
//   pinocchio_step URDF...   →   one line per model: name nv aba_us rnea_us crba_us step_us
#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/joint-configuration.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/parsers/urdf.hpp>
#include <chrono>
#include <cstdio>

using namespace pinocchio;

template <class F> double per_call_us(F f) {
  // repeat until 0.3 s have passed; best of 5 such rounds
  double best = 1e30;
  for (int round = 0; round < 5; ++round) {
    long n = 0;
    auto t0 = std::chrono::steady_clock::now();
    double elapsed = 0;
    while (elapsed < 0.3) {
      for (int i = 0; i < 100; ++i) f();
      n += 100;
      elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }
    best = std::min(best, elapsed / n * 1e6);
  }
  return best;
}

int main(int argc, char** argv) {
  for (int a = 1; a < argc; ++a) {
    Model model;
    pinocchio::urdf::buildModel(argv[a], model, false, true);  // mimic = true
    Data data(model);
    Eigen::VectorXd q = randomConfiguration(model, -Eigen::VectorXd::Ones(model.nq), Eigen::VectorXd::Ones(model.nq));
    Eigen::VectorXd v = Eigen::VectorXd::LinSpaced(model.nv, -1, 1), tau = Eigen::VectorXd::LinSpaced(model.nv, 1, -1);
    Eigen::VectorXd u = Eigen::VectorXd::Zero(model.nv);
    const double h = 0.001;
    Eigen::MatrixXd A(model.nv, model.nv);
    Eigen::LLT<Eigen::MatrixXd> llt(model.nv);
    Eigen::VectorXd v1(model.nv), q1(model.nq);
    bool mimic = model.nvExtended != model.nv;
    double t_aba = mimic ? -1 : per_call_us([&] { aba(model, data, q, v, tau); });
    double t_rnea = per_call_us([&] { rnea(model, data, q, v, tau); });
    double t_crba = per_call_us([&] { crba(model, data, q); });
    double t_step = per_call_us([&] {
      crba(model, data, q);
      data.M.triangularView<Eigen::StrictlyLower>() = data.M.transpose().triangularView<Eigen::StrictlyLower>();
      nonLinearEffects(model, data, q, v);
      A = data.M;
      A.diagonal() += h * model.damping;
      llt.compute(A);
      v1 = llt.solve(data.M * v + h * (u - data.nle));
      q1 = integrate(model, q, h * v1);
    });
    std::printf("%s %d %.3f %.3f %.3f %.3f\n", model.name.c_str(), model.nv, t_aba, t_rnea, t_crba, t_step);
  }
}
