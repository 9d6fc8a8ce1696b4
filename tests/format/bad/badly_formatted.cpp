// A file the format check must refuse (tests/format/check_format.cmake's *_detects_* test): its
// spacing is not what .clang-format says.
int   badly_formatted( int x ){return x+1;}
