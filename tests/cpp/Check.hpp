// Minimal check macro shared by the C++ unit tests: counts failures, prints file:line and a message.
#pragma once
#include <cstdio>

static int failures = 0;
#define CHECK(cond, ...)                                                                                                                             \
	do {                                                                                                                                         \
		if (!(cond)) {                                                                                                                       \
			std::printf("FAIL %s:%d: ", __FILE__, __LINE__);                                                                             \
			std::printf(__VA_ARGS__);                                                                                                    \
			std::printf("\n");                                                                                                           \
			++failures;                                                                                                                  \
		}                                                                                                                                    \
	} while (0)
