#pragma once
// Overloaded{lambdas...}: one visitor from several lambdas, for std::visit over the spec variants. A
// variant alternative no lambda takes is a compile error, which is the point: adding a type to a variant
// makes the compiler name every place that must handle it.
namespace kf {

template <class... Fs>
struct Overloaded : Fs... {
  using Fs::operator()...;
};
template <class... Fs>
Overloaded(Fs...) -> Overloaded<Fs...>;

}  // namespace kf
