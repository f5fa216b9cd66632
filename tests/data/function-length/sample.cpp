// Fixture for tests/function_length_heuristic.sh: constructs the function-length heuristic of
// tools/check-function-length.sh must classify right. Not compiled. Each function's expected
// length (closing line - opening line + 1) is in tests/data/function-length/expected.txt.
#include <string>
#define BRACES_IN_A_MACRO { {
namespace demo {
struct Holder {
  int x_{0};                      // member brace initialiser: not a function
  std::string s_ = "}{";          // braces in a string literal
  Holder(int x, int y) : x_{x}, s_("{") {  // brace in a member initialiser list
    x_ += y;
  }
  int get() const noexcept { return x_; }
};
const char* raw = R"x(} } { ")x";
auto f(int a) -> int {
  auto g = [a](int b) {  // a lambda counts to its enclosing function
    return a + b;
  };
  /* } a block comment { */
  const char c = '}';
  const long n = 1'000'000;
  return g(c) + static_cast<int>(n);
}
class Runner {
 public:
  Runner(const std::string& name, int v)
      : name_(name),
        hook_([this](int x) { return x + v_; }),
        v_(v) {
    name_ += "x";
  }
 private:
  std::string name_;
  int (*hook_)(int);
  int v_;
};
void defaults(int x = {}) {
  if (x) {
    x = 2;
  }
}
enum class Kind : unsigned char { a, b };
template <class T>
T twice(T v)
{
  return v + v;
}
extern "C" {
int c_entry(void) { return 0; }
}
}  // namespace demo
