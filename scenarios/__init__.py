"""Shipped scenario files, installed as package data of `harness`."""
