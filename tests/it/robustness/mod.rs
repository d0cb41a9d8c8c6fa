//! Robustness: malformed and fuzzed input (byte-level and structural
//! mutations), bounded reads, one wording of CSV refusals, extreme values,
//! very wide lines, option ranges, atomic writes, output errors (closed pipe,
//! full device), and the recorded outputs compared byte for byte.

mod atomic_writes;
mod bounded_reads;
mod csv_messages;
mod extreme_values;
mod fuzz;
mod fuzz_structured;
mod golden_outputs;
mod library_words;
mod malformed_input;
mod option_ranges;
mod output_errors;
mod wide_lines;
