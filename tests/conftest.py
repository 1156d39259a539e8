"""Shared settings for the harness's own tests."""
