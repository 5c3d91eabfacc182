/* parser.h — script text to syntax tree.
 *
 * parse_source tokenises and parses source `src` (already added to the
 * state) into an N_BLOCK of statements allocated in the state's arena.
 * On a syntax error it records the error (I->err; err.incomplete is set when
 * the input merely ended too early, which the REPL uses to ask for more).
 *
 * Nesting is limited: more than PARSE_MAX_NESTING brackets, blocks, unary
 * operators, `^`, `not`, `if`, `=>` or `fn` inside each other is a syntax
 * error at the token that went too deep ("nested too deeply"), so every walk
 * over a syntax tree recurses at most that far into nested constructs. Long
 * flat chains (`1+1+…+1`, `x |> f |> g …`, `a.b.c…`) are built by loops and
 * are not limited here; the evaluator and resolver are bounded on them by
 * the C stack check (cstack.h).
 */
#ifndef PARSER_H
#define PARSER_H

#include "state.h"

#define PARSE_MAX_NESTING 200

int parse_source(interp *I, int src, node **out);

#endif
