"""The harness's own participants announce every 0.25 s; nothing it starts sees the profile."""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET

import pytest

from harness.ros.announcements import PROFILE, SETTINGS, harness_announcements


def test_the_profile_is_set_only_while_the_harness_creates_participants(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    for name in SETTINGS:
        monkeypatch.delenv(name, raising=False)
    with harness_announcements():
        assert os.environ[SETTINGS[0]] == str(PROFILE)
    assert not any(name in os.environ for name in SETTINGS)


def test_a_users_own_profile_file_wins(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("FASTDDS_DEFAULT_PROFILES_FILE", "/home/me/dds.xml")
    monkeypatch.delenv(SETTINGS[0], raising=False)
    with harness_announcements():
        assert SETTINGS[0] not in os.environ
    assert os.environ["FASTDDS_DEFAULT_PROFILES_FILE"] == "/home/me/dds.xml"


def test_the_profile_announces_every_quarter_second() -> None:
    ns = {"d": "http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles"}
    root = ET.parse(PROFILE).getroot()
    participant = root.find("d:profiles/d:participant", ns)
    assert participant is not None and participant.get("is_default_profile") == "true"
    period = participant.find("d:rtps/d:builtin/d:discovery_config/d:leaseAnnouncement", ns)
    assert period is not None
    assert period.findtext("d:sec", namespaces=ns) == "0"
    assert period.findtext("d:nanosec", namespaces=ns) == "250000000"
