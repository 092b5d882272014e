// `crowddb fit-kernel --from R1 --to R2 [--alpha a] [--samples N]`: least-squares A and k of
// A e^{-k x} against alpha / x on [R1, R2] (DESIGN.md §4), to pick one's own kernel constants.
#include "commands.hpp"
#include "crowddb/query.hpp"

namespace crowddb::cli {

void add_fit_kernel_command(CLI::App& app, Action& action) {
  auto* sub = app.add_subcommand("fit-kernel",
                                 "least-squares A, k of A e^{-k x} against alpha/x on [from, to]");
  static double from = 0, to = 0, alpha = 1;
  static int samples = 0;
  sub->add_option("--from", from, "left end R1 of the interval (> 0)")->required();
  sub->add_option("--to", to, "right end R2 of the interval (> R1)")->required();
  sub->add_option("--alpha", alpha, "numerator of alpha/x")->capture_default_str();
  sub->add_option(
         "--samples", samples,
         "0: continuous L2 norm on the interval (default); N >= 2: N equally spaced sample points")
      ->capture_default_str();
  sub->callback([&action] {
    action = [] {
      const KernelFit f = fit_exp_kernel(from, to, alpha, samples);
      std::string text;
      text += "A: " + format_number(f.A) + "\n";
      text += "k: " + format_number(f.k) + "\n";
      text += "max_abs_error: " + format_number(f.max_abs_error) + "\n";
      text += "max_rel_error: " + format_number(f.max_rel_error) + "\n";
      text += "rms_error: " + format_number(f.rms_error) + "\n";
      write_output("-", text);
      return 0;
    };
  });
}

}  // namespace crowddb::cli
