"""The OpenCascade side of surfprep: conversion, STEP/IGES, CLI, OpenCascade references."""
