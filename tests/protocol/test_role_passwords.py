"""The role passwords' format, written once in protocol: what ``cnc web-users`` writes, the
OPC UA front end and cnc-web read back (protocol/role_passwords.py)."""

from __future__ import annotations

import pytest

from cnc_objects.protocol.role_passwords import (
    RolePasswords,
    format_role_passwords,
    parse_role_passwords,
)
from cnc_objects.protocol.roles import Role


def test_passwords_written_read_back_and_check() -> None:
    passwords = RolePasswords()
    passwords.set_password(Role.ADMIN, "a")
    passwords.set_password(Role.MONITOR, "m")
    text = format_role_passwords(passwords)
    assert '"a"' not in text and '"m"' not in text  # hashes only, never a password
    read = parse_role_passwords(text, "users.json")
    assert read.roles == [Role.MONITOR, Role.ADMIN]
    assert read.verify(Role.ADMIN, "a") and not read.verify(Role.ADMIN, "m")
    assert not read.verify(Role.OPERATOR, "")  # a role without a password never signs in


@pytest.mark.parametrize(("text", "problem"), [
    ("not json", "Expecting value"),
    ("[]", "list indices"),
    ('{"version": 2, "roles": {}}', "version 2, expected 1"),
    ('{"version": 1, "roles": {"root": "$argon2id$..."}}', "unknown role 'root'"),
    ('{"version": 1}', "'roles'"),
])
def test_a_file_that_is_not_one_is_named_with_the_problem(text: str, problem: str) -> None:
    with pytest.raises(ValueError, match=f"^users.json is not a web users file: .*{problem}"):
        parse_role_passwords(text, "users.json")


def test_a_stored_hash_that_is_not_one_checks_no_password() -> None:
    read = parse_role_passwords('{"version": 1, "roles": {"operator": "plain"}}', "f")
    assert not read.verify(Role.OPERATOR, "plain")
