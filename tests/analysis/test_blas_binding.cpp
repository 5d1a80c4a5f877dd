// The BLAS that CHOLMOD's supernodal factorisation (the HHD's Laplacian factor) calls: with
// OpenBLAS found at configure time the programs link it ahead of the system's libblas.so.3, so
// the loader's global scope (where libcholmod's undefined dgemm_ etc. are looked up) resolves
// them to OpenBLAS whatever the libblas.so.3 alternative is (CMakeLists.txt, docs/hhd.md).
#include <dlfcn.h>
#include <gtest/gtest.h>

#include <string>

namespace {

std::string library_of(const char* symbol) {
  void* address = dlsym(RTLD_DEFAULT, symbol);
  if (address == nullptr) return "";
  Dl_info info{};
  if (dladdr(address, &info) == 0 || info.dli_fname == nullptr) return "";
  return info.dli_fname;
}

}  // namespace

TEST(BlasBinding, CholmodsBlasAndLapackCallsResolveToOpenBlas) {
#ifndef GS_OPENBLAS
  GTEST_SKIP() << "OpenBLAS was not found at configure time (apt-get install libopenblas-dev)";
#else
  for (const char* symbol : {"dgemm_", "dsyrk_", "dtrsm_", "dpotrf_"}) {
    const std::string lib = library_of(symbol);
    EXPECT_NE(lib.find("openblas"), std::string::npos) << symbol << " resolves to '" << lib << "'";
  }
#endif
}
