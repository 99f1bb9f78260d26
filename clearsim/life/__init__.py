"""`clearsim life`: wear over a machine's service life, block by block (docs/life.md)."""
