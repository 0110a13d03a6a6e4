"""The wire and nothing else: ADS vocabulary, return codes, data types, frames. No I/O."""
