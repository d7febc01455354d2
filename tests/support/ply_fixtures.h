// Binary PLY fixtures for the tests: values of any type in either byte order.
#pragma once
#include <algorithm>
#include <cstring>
#include <string>

template <class T>
void put(std::string& out, T v, bool big_endian) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  if (big_endian) std::reverse(b, b + sizeof(T));
  out.append(b, sizeof(T));
}
