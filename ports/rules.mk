# ports/rules.mk — the rule every recipe ports/<target>/<name>.mk includes. Run from the top
# directory:   make -f ports/arm-linux/arm.mk      ->  ports/build/arm/pray
# A recipe sets NAME, CXX, PORTFLAGS (code generation), LDFLAGS, EXE, RUN (the emulator prefix
# that runs the program here: empty for a native program, `-` for one that cannot run here),
# CONFIG (its prayconf.h) and PACKAGES (the Debian packages ports/check installs for it). It may
# add POSTLINK (a command run on the program after linking), EXTRA (more files to build) and
# REFERENCE = float (ports/check then compares its images with a native single-precision pray).
STD   ?= -std=c++98
WARN  ?= -Wall -Wextra -pedantic
OUT    = ports/build/$(NAME)
FLAGS  = $(STD) $(PORTFLAGS) $(WARN) -fno-exceptions -fno-rtti -DPRAY_USER_CONFIG='"$(CONFIG)"'

all: $(OUT)/pray$(EXE) $(EXTRA)

$(OUT)/pray$(EXE): pray.cpp pray.hpp $(CONFIG)
	@mkdir -p $(OUT)
	$(CXX) $(FLAGS) -DPRAY_MAIN pray.cpp -o $@ $(LDFLAGS) -lm
	$(POSTLINK)

# The program's own object code, for inspection (ports/i486/scan486).
$(OUT)/pray.o: pray.cpp pray.hpp $(CONFIG)
	@mkdir -p $(OUT)
	$(CXX) $(FLAGS) -DPRAY_MAIN -c pray.cpp -o $@

# For ports/check: the recipe's settings as shell assignments.
vars:
	@echo "CXX='$(CXX)' EXE='$(EXE)' RUN='$(RUN)' PACKAGES='$(PACKAGES)' OUT='$(OUT)' REFERENCE='$(REFERENCE)'"

.PHONY: all vars
