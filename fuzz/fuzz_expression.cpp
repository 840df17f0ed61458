// System files with expressions (roots/equilibria --system): the expression parser, then one
// evaluation of the compiled program in doubles and in dual numbers.
#include "fuzz_common.hpp"
#include "ddemap/problem/expression.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    return ddemap::fuzz::expect_value_or_bad_input([&] {
        const ddemap::ExpressionNames names{{"x", "y"}, {"a", "tau"}};
        const std::string text = ddemap::fuzz::text(data, size);
        const ddemap::ParsedEquations pe = ddemap::parse_equations({"y", text}, names);
        const std::size_t slots = pe.delays.size() + 1;
        std::vector<double> u(2 * slots, 0.5);
        std::vector<ddemap::Dual<double>> ud(2 * slots, ddemap::Dual<double>(0.5, 1.0));
        const double p[2] = {1.5, 2.0};
        const ddemap::Dual<double> pd[2] = {1.5, 2.0};
        (void)pe.equations[1].evaluate<double>(u.data(), p);
        (void)pe.equations[1].evaluate<ddemap::Dual<double>>(ud.data(), pd);
        for (const auto& d : pe.delays) (void)d.evaluate<double>(nullptr, p);
        (void)ddemap::parse_parameter_expression(text, {"a", "tau"}, "fuzz");
    });
}
