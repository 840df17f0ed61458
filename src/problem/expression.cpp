#include "ddemap/problem/expression.hpp"

#include "core/internal/text.hpp"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <stdexcept>

namespace ddemap {

namespace {

using Op = Expression::Op;
using Instruction = Expression::Instruction;

struct Function {
    const char* name;
    Op op;
    int arity;
};

constexpr Function functions[] = {
    {"exp", Op::Exp, 1},   {"log", Op::Log, 1},   {"sqrt", Op::Sqrt, 1}, {"sin", Op::Sin, 1}, {"cos", Op::Cos, 1},
    {"tan", Op::Tan, 1},   {"tanh", Op::Tanh, 1}, {"abs", Op::Abs, 1},   {"min", Op::Min, 2}, {"max", Op::Max, 2},
    {"pow", Op::Pow, 2},
};

const Function* find_function(const std::string& name) {
    for (const Function& f : functions)
        if (name == f.name) return &f;
    return nullptr;
}

int find(const std::vector<std::string>& list, const std::string& name) {
    const auto it = std::find(list.begin(), list.end(), name);
    return it == list.end() ? -1 : static_cast<int>(it - list.begin());
}

std::string list_of(const std::vector<std::string>& names) {
    std::string s;
    for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
    return s.empty() ? "none" : s;
}

/// A term under construction: its program and whether it is a number only (then folded).
struct Code {
    std::vector<Instruction> program;
    bool reads_state = false;
    bool is_number() const { return program.size() == 1 && program[0].op == Op::Number; }
    double number() const { return program[0].number; }
};

Code number_code(double x) { return {{{Op::Number, 0, x}}, false}; }

double apply(Op op, double a, double b) {
    switch (op) {
    case Op::Add: return a + b;
    case Op::Sub: return a - b;
    case Op::Mul: return a * b;
    case Op::Div: return a / b;
    case Op::Pow: return std::pow(a, b);
    case Op::Min: return std::min(a, b);
    case Op::Max: return std::max(a, b);
    case Op::Neg: return -a;
    case Op::Exp: return std::exp(a);
    case Op::Log: return std::log(a);
    case Op::Sqrt: return std::sqrt(a);
    case Op::Sin: return std::sin(a);
    case Op::Cos: return std::cos(a);
    case Op::Tan: return std::tan(a);
    case Op::Tanh: return std::tanh(a);
    case Op::Abs: return std::abs(a);
    default: return a;
    }
}

class Parser {
public:
    Parser(const std::string& text, const ExpressionNames& names, std::string where, ParsedEquations* shared)
        : m_text(text), m_names(names), m_where(std::move(where)), m_shared(shared) {}

    /// The whole text as one expression; parameter_only: no variable may appear.
    Code parse_all(bool parameter_only) {
        m_parameter_only = parameter_only;
        skip();
        if (m_pos >= m_text.size()) fail(m_pos, "the expression is empty", "an expression");
        Code c = expression();
        skip();
        if (m_pos < m_text.size()) fail(m_pos, "unexpected " + detail::quoted(std::string(1, m_text[m_pos])), "an operator (+ - * / ^) or the end");
        return c;
    }

private:
    [[noreturn]] void fail(std::size_t pos, const std::string& what, const std::string& expected) const {
        throw std::invalid_argument(m_where + ", character " + std::to_string(pos + 1) + ": " + what + ": expected " + expected);
    }

    void skip() {
        while (m_pos < m_text.size() && std::isspace(static_cast<unsigned char>(m_text[m_pos]))) ++m_pos;
    }
    bool accept(char c) {
        skip();
        if (m_pos < m_text.size() && m_text[m_pos] == c) {
            ++m_pos;
            return true;
        }
        return false;
    }
    void expect(char c, const std::string& expected) {
        skip();
        if (m_pos >= m_text.size()) fail(m_pos, "the expression ends early", expected);
        if (m_text[m_pos] != c) fail(m_pos, "unexpected " + detail::quoted(std::string(1, m_text[m_pos])), expected);
        ++m_pos;
    }

    struct Depth {
        explicit Depth(Parser& p) : m_p(p) {
            if (++m_p.m_depth > 200) m_p.fail(m_p.m_pos, "the expression is nested too deeply", "at most 200 levels");
        }
        ~Depth() { --m_p.m_depth; }
        Parser& m_p;
    };

    static Code binary(Op op, Code a, Code b) {
        if (a.is_number() && b.is_number()) return number_code(apply(op, a.number(), b.number()));
        if (op == Op::Pow && b.is_number()) {
            a.program.push_back({Op::PowNumber, 0, b.number()});
            return a;
        }
        a.program.insert(a.program.end(), b.program.begin(), b.program.end());
        a.program.push_back({op, 0, 0.0});
        a.reads_state = a.reads_state || b.reads_state;
        return a;
    }
    static Code unary(Op op, Code a) {
        if (a.is_number()) return number_code(apply(op, a.number(), 0.0));
        a.program.push_back({op, 0, 0.0});
        return a;
    }

    Code expression() {
        Depth d(*this);
        Code c = term();
        for (;;) {
            if (accept('+')) c = binary(Op::Add, std::move(c), term());
            else if (accept('-')) c = binary(Op::Sub, std::move(c), term());
            else return c;
        }
    }
    Code term() {
        Code c = signed_factor();
        for (;;) {
            if (accept('*')) c = binary(Op::Mul, std::move(c), signed_factor());
            else if (accept('/')) c = binary(Op::Div, std::move(c), signed_factor());
            else return c;
        }
    }
    Code signed_factor() {
        Depth d(*this);
        if (accept('-')) return unary(Op::Neg, signed_factor());
        if (accept('+')) return signed_factor();
        Code base = primary();
        if (accept('^')) return binary(Op::Pow, std::move(base), signed_factor());
        return base;
    }

    Code primary() {
        Depth d(*this);
        skip();
        if (m_pos >= m_text.size()) fail(m_pos, "the expression ends early", "a number, a name or '('");
        const char c = m_text[m_pos];
        if (c == '(') {
            ++m_pos;
            Code e = expression();
            expect(')', "')'");
            return e;
        }
        if (std::isdigit(static_cast<unsigned char>(c)) || c == '.') return number();
        if (std::isalpha(static_cast<unsigned char>(c)) || c == '_') return name();
        fail(m_pos, "unexpected " + detail::quoted(std::string(1, c)), "a number, a name or '('");
    }

    Code number() {
        const std::size_t start = m_pos;
        std::size_t digits = 0;
        while (m_pos < m_text.size() && std::isdigit(static_cast<unsigned char>(m_text[m_pos]))) ++m_pos, ++digits;
        if (m_pos < m_text.size() && m_text[m_pos] == '.') {
            ++m_pos;
            while (m_pos < m_text.size() && std::isdigit(static_cast<unsigned char>(m_text[m_pos]))) ++m_pos, ++digits;
        }
        if (digits == 0) fail(start, "'.' is not a number", "digits");
        if (m_pos < m_text.size() && (m_text[m_pos] == 'e' || m_text[m_pos] == 'E')) {
            std::size_t p = m_pos + 1;
            if (p < m_text.size() && (m_text[p] == '+' || m_text[p] == '-')) ++p;
            if (p >= m_text.size() || !std::isdigit(static_cast<unsigned char>(m_text[p])))
                fail(p, "the exponent of the number has no digits", "digits after 'e'");
            while (p < m_text.size() && std::isdigit(static_cast<unsigned char>(m_text[p]))) ++p;
            m_pos = p;
        }
        const std::string token = m_text.substr(start, m_pos - start);
        const double x = std::strtod(token.c_str(), nullptr);
        if (!std::isfinite(x)) fail(start, "the number " + token + " is out of range", "a finite number");
        return number_code(x);
    }

    Code name() {
        const std::size_t start = m_pos;
        while (m_pos < m_text.size() && (std::isalnum(static_cast<unsigned char>(m_text[m_pos])) || m_text[m_pos] == '_')) ++m_pos;
        const std::string id = m_text.substr(start, m_pos - start);
        skip();
        const bool call = m_pos < m_text.size() && m_text[m_pos] == '(';
        if (const Function* f = find_function(id)) {
            if (!call) fail(m_pos, "the function " + id + " has no argument list", id + "(...)");
            ++m_pos;
            Code a = expression();
            if (f->arity == 2) {
                expect(',', "',' and the second argument of " + id);
                Code b = expression();
                expect(')', "')' after the two arguments of " + id);
                return binary(f->op, std::move(a), std::move(b));
            }
            skip();
            if (m_pos < m_text.size() && m_text[m_pos] == ',') fail(m_pos, id + " takes one argument", "')'");
            expect(')', "')' after the argument of " + id);
            return unary(f->op, std::move(a));
        }
        const int p = find(m_names.parameters, id);
        if (p >= 0) {
            if (call) fail(m_pos, "the parameter " + id + " is not a function", "an operator after it");
            return {{{Op::Parameter, p, 0.0}}, false};
        }
        const int v = find(m_names.variables, id);
        if (v >= 0) {
            if (m_parameter_only)
                fail(start, "the delay depends on the state (" + id + ")", "an expression of parameters and numbers");
            if (!call) return {{{Op::State, v, 0.0}}, true};
            return delayed(v, id);
        }
        if (id == "t") fail(start, "the time t appears outside a delayed value", "t only in NAME(t - DELAY)");
        fail(start, "unknown name '" + id + "'",
             m_parameter_only ? "a parameter (" + list_of(m_names.parameters) + ") or a function"
                              : "a variable (" + list_of(m_names.variables) + "), a parameter (" + list_of(m_names.parameters) +
                                    ") or a function");
    }

    /// NAME(t) or NAME(t - DELAY), after NAME.
    Code delayed(int v, const std::string& id) {
        ++m_pos;  // '('
        skip();
        const std::size_t tpos = m_pos;
        if (!(m_pos < m_text.size() && m_text[m_pos] == 't' &&
              (m_pos + 1 >= m_text.size() || !(std::isalnum(static_cast<unsigned char>(m_text[m_pos + 1])) || m_text[m_pos + 1] == '_'))))
            fail(tpos, "a delayed value of " + id + " must read " + id + "(t - DELAY)", "'t'");
        ++m_pos;
        if (accept(')')) return {{{Op::State, v, 0.0}}, true};
        expect('-', "'-' after t (" + id + "(t - DELAY))");
        const std::size_t dstart = m_pos;
        const bool outer = m_parameter_only;
        m_parameter_only = true;
        Code delay = expression();
        m_parameter_only = outer;
        const std::size_t dend = m_pos;
        expect(')', "')' closing " + id + "(t - DELAY)");
        if (delay.is_number() && delay.number() == 0.0) return {{{Op::State, v, 0.0}}, true};
        if (!m_shared) fail(dstart, "a delayed value inside a delay", "an expression of parameters and numbers");
        const Expression e(std::move(delay.program));
        auto& ds = m_shared->delays;
        int k = static_cast<int>(std::find(ds.begin(), ds.end(), e) - ds.begin());
        if (k == static_cast<int>(ds.size())) {
            ds.push_back(e);
            std::string t = m_text.substr(dstart, dend - dstart);
            t.erase(0, t.find_first_not_of(' '));
            t.erase(t.find_last_not_of(' ') + 1);
            m_shared->delay_texts.push_back(t);
        }
        // slot k + 1; the block size n is applied once all equations are read
        return {{{Op::State, v + (k + 1) * block_marker, 0.0}}, true};
    }

public:
    static constexpr int block_marker = 1 << 20;  // temporary encoding of the delay slot

private:
    const std::string& m_text;
    const ExpressionNames& m_names;
    std::string m_where;
    ParsedEquations* m_shared;
    std::size_t m_pos = 0;
    int m_depth = 0;
    bool m_parameter_only = false;
};

}  // namespace

Expression::Expression(std::vector<Instruction> program) : m_program(std::move(program)) {
    int depth = 0;
    for (const Instruction& in : m_program) {
        switch (in.op) {
        case Op::Number:
        case Op::State:
        case Op::Parameter: ++depth; break;
        case Op::Add: case Op::Sub: case Op::Mul: case Op::Div: case Op::Pow: case Op::Min: case Op::Max:
            if (depth < 2) throw std::invalid_argument("an expression program pops an empty stack: expected a valid postfix program");
            --depth;
            break;
        default:
            if (depth < 1) throw std::invalid_argument("an expression program pops an empty stack: expected a valid postfix program");
        }
        m_depth = std::max(m_depth, depth);
    }
    if (!m_program.empty() && depth != 1) throw std::invalid_argument("an expression program leaves " + std::to_string(depth) + " values: expected 1");
}

bool Expression::is_parameter_only() const {
    return std::none_of(m_program.begin(), m_program.end(), [](const Instruction& i) { return i.op == Op::State; });
}

void ExpressionNames::check_name(const std::string& name, const std::string& what) {
    bool ok = !name.empty() && (std::isalpha(static_cast<unsigned char>(name[0])) || name[0] == '_');
    for (char c : name) ok = ok && (std::isalnum(static_cast<unsigned char>(c)) || c == '_');
    if (!ok) throw std::invalid_argument(what + " " + detail::quoted(name) + " is not a name: expected letters, digits and '_', starting with a letter");
    if (find_function(name)) throw std::invalid_argument(what + " " + detail::quoted(name) + " is the name of a function: expected another name");
    if (name == "t") throw std::invalid_argument(what + " 't' is the time: expected another name");
}

ParsedEquations parse_equations(const std::vector<std::string>& equations, const ExpressionNames& names) {
    if (equations.size() != names.variables.size())
        throw std::invalid_argument(std::to_string(equations.size()) + " equations for " + std::to_string(names.variables.size()) +
                                    " variables: expected one equation per variable");
    ParsedEquations out;
    std::vector<Code> codes;
    for (std::size_t j = 0; j < equations.size(); ++j) {
        Parser parser(equations[j], names, "equation " + std::to_string(j + 1) + " (d" + names.variables[j] + "/dt)", &out);
        codes.push_back(parser.parse_all(false));
    }
    const int n = static_cast<int>(names.variables.size());
    for (Code& c : codes) {
        for (Instruction& in : c.program)
            if (in.op == Op::State) in.index = (in.index / Parser::block_marker) * n + in.index % Parser::block_marker;
        out.equations.emplace_back(std::move(c.program));
    }
    return out;
}

Expression parse_parameter_expression(const std::string& text, const std::vector<std::string>& parameters, const std::string& where) {
    ExpressionNames names;
    names.parameters = parameters;
    Parser parser(text, names, where, nullptr);
    return Expression(parser.parse_all(true).program);
}

}  // namespace ddemap
