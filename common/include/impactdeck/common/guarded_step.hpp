#pragma once
// A step of a third-party library (Gmsh throws std::string, std::exception or anything) turned into
// one InputError naming the file and the step, with the library's last logged error appended.
#include <exception>
#include <string>
#include <utility>

#include "impactdeck/common/error.hpp"

namespace impactdeck {

/// Runs `f()`. impactdeck's own errors pass through; anything else thrown becomes
/// where.error(step, what [+ " (" + last_error() + ")" when that differs]).
template <class F, class LastError>
void run_as_input_error(const InputContext& where, const std::string& step, F&& f, LastError&& last_error) {
  std::string what;
  try {
    std::forward<F>(f)();
    return;
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    what = e.what();
  } catch (const std::string& e) {
    what = e;
  } catch (...) {
    what = "unknown error";
  }
  const std::string last = last_error();
  if (!last.empty() && last != what) what += " (" + last + ")";
  throw where.error(step, what);
}

/// The same, naming the file `where` alone.
template <class F, class LastError>
void run_as_input_error(const std::string& where, const std::string& step, F&& f, LastError&& last_error) {
  run_as_input_error(InputContext{where, ""}, step, std::forward<F>(f), std::forward<LastError>(last_error));
}

}  // namespace impactdeck
